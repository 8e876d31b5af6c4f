"""The one protocol every task kind implements, and the typed report it returns.

A runner is built from a checked task and a :class:`~robocfg.engine.options.RunOptions`;
``check()`` runs the checks that need no simulation (exit 2 before anything is simulated),
``run()`` simulates and returns a :class:`RunOutput`: the report (the ``--json`` payload, the same
for the same seed) and the wall-clock timing kept apart from it. A run that cannot succeed
raises ``RunFailed(phase, reason, report=...)``; a stopped run (``should_stop``) returns its
report with ``interrupted`` set.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import Counter
from collections.abc import Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Generic, Literal, Protocol, TypeVar

from robocfg.engine.options import EpisodeOutcome, RunOptions

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.config.robot import RobotConfig
    from robocfg.engine.dataset import ReplayScene
    from robocfg.errors import Problem


@dataclass
class TableView:
    """A table of a report for people: a title, column names, rows of strings."""

    title: str
    columns: list[str]
    rows: list[list[str]]


@dataclass
class ReportView:
    """What a front-end shows of a report: warnings, a title over (key, value) rows, more tables,
    notes, the failure lines, and a status (``ok``, ``warn`` or ``failed`` with its text)."""

    title: str
    rows: list[tuple[str, str]]
    tables: list[TableView] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    failures: list[str] = field(default_factory=list)
    footer: list[str] = field(default_factory=list)
    status: Literal["ok", "warn", "failed"] = "ok"
    status_text: str = ""


class RunReport(Protocol):
    """The typed report of any kind (a dataclass: its fields are the JSON report)."""

    interrupted: bool

    def view(self, timing: Any) -> ReportView: ...

    def summary_line(self, timing: Any) -> str: ...

    def failure_lines(self) -> list[str]: ...

    def passed(self, min_success: float) -> bool: ...

    def episodes_finished(self) -> int: ...


ReportT = TypeVar("ReportT")


@dataclass
class RunOutput(Generic[ReportT]):
    """A finished run: the report (deterministic for a seed) and its wall-clock timing."""

    report: ReportT
    timing: Any = None


def failure_lines(episodes: Sequence[EpisodeOutcome]) -> list[str]:
    """One line per distinct (phase, reason) among the failed episodes, most frequent first."""
    counts = Counter((e.failed_phase or "?", e.reason) for e in episodes if not e.success)
    return [f"{n} × {phase}: {reason}" for (phase, reason), n in counts.most_common()]


class EpisodesReport:
    """Methods of :class:`RunReport` for a report whose ``episodes`` are outcome records (each
    with ``success``, ``failed_phase``, ``reason``): mix it into the report dataclass and
    override ``view`` / ``summary_line`` for kind-specific figures."""

    episodes: list[Any]
    interrupted: bool
    title: ClassVar[str] = "run"

    def passed(self, min_success: float) -> bool:
        n = len(self.episodes)
        return n > 0 and sum(e.success for e in self.episodes) / n >= min_success

    def failure_lines(self) -> list[str]:
        return failure_lines(self.episodes)

    def episodes_finished(self) -> int:
        return len(self.episodes)

    def summary_line(self, timing: Any = None) -> str:
        n, ok = len(self.episodes), sum(e.success for e in self.episodes)
        return f"{'ok' if ok == n else 'failed'}: {ok}/{n} episodes succeeded"

    def view(self, timing: Any = None) -> ReportView:
        n, ok = len(self.episodes), sum(e.success for e in self.episodes)
        return ReportView(self.title, [("episodes", str(n)), ("success", f"{ok}/{n}")],
                          failures=self.failure_lines(), status="ok" if ok == n else "failed")


def check_arm_option(robot: RobotConfig, arm: str | None) -> None:
    """``--arm NAME`` must name an arm of ``robot``: else ``ConfigError`` reading
    ``--arm NAME: robot 'r' has no arm 'NAME'; did you mean 'right'? (its arms: left, right)``."""
    from robocfg.errors import ConfigError, Problem
    from robocfg.suggest import did_you_mean

    names = [a.name for a in robot.arms]
    if arm is None or arm in names:
        return
    if len(names) == 1:
        message = (f"robot {robot.name!r} has one arm, {names[0]!r}: leave --arm out or give --arm {names[0]}")
    else:
        message = (f"robot {robot.name!r} has no arm {arm!r}{did_you_mean(arm, names)} "
                   f"(its arms: {', '.join(names)})")
    raise ConfigError([Problem(f"--arm {arm}", None, None, "", message)])


class TaskCommand:
    """What the command line shows of a kind before anything runs: its name, help, own options
    and whether it has episodes (``robocfg run KIND --help`` and the option parsing need no more).
    Every runner is one; a built-in kind also declares its own in a light module
    (``robocfg.runners.<kind>_command``) that its runner subclasses, so ``--help`` loads no
    episode code (``robocfg.engine.registry.command_for``)."""

    kind: ClassVar[str]  # the YAML's `task:` value; `robocfg run <kind with - for _>`
    Options: ClassVar[type | None] = None  # the kind's own options (a dataclass of option(...) fields)
    summary: ClassVar[str] = ""  # one line: the command's short help
    description: ClassVar[str] = ""  # the command's help text
    verb: ClassVar[str] = "succeeded"  # progress bar: "3 placed"
    episodic: ClassVar[bool] = False  # runs several seeded episodes (--episodes > 1)

    @classmethod
    def static_problems(cls, task: CheckedTask, arm: str | None = None) -> list[Problem]:
        """What ``validate`` reports for a task of this kind beyond its schema and cross-checks:
        checks that need no simulation but do need the kinematics (IK reach of the task's poses),
        with their severity. ``run`` makes the same checks in :meth:`TaskRunner.check`. Default:
        none. A built-in kind defines them on its command face, so ``validate`` loads the
        kinematics they need, not the episode code."""
        return []


class TaskRunner(TaskCommand, ABC):
    """Base of every task kind's runner; subclasses set the class attributes and ``run``."""

    params: ClassVar[type]  # model of the YAML's `<kind>:` block
    report: ClassVar[type]  # report dataclass (its JSON Schema: `robocfg schema report-<kind>`)

    def __init__(self, task: CheckedTask, options: RunOptions | None = None):
        self.task = task
        self.options = options if options is not None else RunOptions()
        if self.Options is not None and self.options.extras is None:
            import dataclasses

            self.options = dataclasses.replace(self.options, extras=self.Options())

    def check(self) -> None:
        """Checks needing no simulation, run before anything is simulated (raise ``ConfigError``,
        ``NotFound`` or ``RobocfgError``). The default checks the arm name and the episode count."""
        from robocfg.errors import ConfigError, Problem

        check_arm_option(self.task.robots[0].config, self.options.arm)
        if not self.episodic and self.options.episodes != 1:
            raise ConfigError([Problem("--episodes", None, None, "",
                                       f"'run {self.kind}' runs one episode (it has nothing to randomise), "
                                       f"got {self.options.episodes}")])

    @abstractmethod
    def run(self) -> RunOutput: ...

    def open_session(self) -> Any:
        """The per-process session (``run(k)``, ``close()``); a one-episode kind runs whole as
        episode 0. Episodic kinds build their world here."""
        from robocfg.engine.session import SingleRunSession

        return SingleRunSession(self)

    def replay_scene(self, k: int) -> AbstractContextManager[ReplayScene]:
        """A context giving episode ``k``'s world as its dataset recording began (the recorded
        actions then drive it: ``robocfg dataset replay``). Kinds that record datasets give one."""
        from robocfg.errors import RobocfgError

        raise RobocfgError(f"'{self.kind}' runs cannot be replayed")
