"""What a run is asked to do besides the task itself: one :class:`RunOptions` for every kind.

The command line, the Python API, the executors and the Gym environments all fill this one
dataclass; a kind's own options (trajectory ``--plot``, follow-target ``--with-obstacle``...)
are a dataclass of the kind's, held in ``extras``, whose fields declare their command-line flag
with :func:`option` so the CLI factory can offer them without the kind importing the CLI.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from robocfg.engine.dataset import EpisodeSink
    from robocfg.sim.world import World


class EpisodeOutcome(Protocol):
    """The fields of an episode record that progress bars and failure summaries read."""

    success: bool
    failed_phase: str | None
    reason: str


class FrameRecorder(Protocol):
    """What watches one episode (``robocfg.sim.record.Recorder`` and its kin, or any
    :class:`EpisodeObserver`): ``maybe_capture`` after every physics step, ``set_phase`` when a
    phase begins, ``finish`` with the outcome, ``save`` at the end."""

    def maybe_capture(self) -> None: ...

    def set_phase(self, name: str) -> None: ...

    def finish(self, success: bool, reason: str = "") -> None: ...

    def save(self) -> Path | None: ...


class EpisodeObserver:
    """A :class:`FrameRecorder` that does nothing: subclass it and override what you watch (a
    test's contact spy overrides ``maybe_capture`` only)."""

    def maybe_capture(self) -> None:
        """Called after every physics step of the episode."""

    def set_phase(self, name: str) -> None:
        """Called when phase ``name`` begins."""

    def finish(self, success: bool, reason: str = "") -> None:
        """Called once the episode has ended (``reason``: ``phase: why`` of a failure)."""

    def save(self) -> Path | None:
        """Called last; a recorder writes its file and returns its path."""
        return None


RecorderFactory = Callable[["World"], FrameRecorder]


@dataclass(frozen=True)
class RunOptions:
    """How to run a checked task. Every field has a default, so ``RunOptions()`` runs the task
    as its YAML says.

    The callbacks (``on_episode``, ``should_stop``, ``log``) and ``recorder`` are for the process
    running the episodes; :meth:`portable` drops them so the options can be pickled into an
    :class:`robocfg.engine.EpisodeSpec`.
    """

    seed: int | None = None  # random seed (>= 0); None: the task's sim.seed
    episodes: int = 1  # episodes of a batch run; episode k is seeded with rng([seed, k])
    arm: str | None = None  # arm of a multi-arm robot (None: the first)
    gui: bool = False  # the PyBullet GUI instead of headless DIRECT
    record: Path | None = None  # picture file of one episode: .gif/.mp4 (animation), .png (last frame)
    record_episode: int = 0  # which episode ``record`` films
    recorder: RecorderFactory | None = None  # custom recorder for ``record_episode`` (overrides ``record``)
    recording: Any = None  # robocfg.sim.record_settings.RecordSettings: --camera/--size/--fps of ``record``
    extras: Any = None  # the kind's own options: an instance of its ``Options`` dataclass, or None
    on_episode: Callable[[EpisodeOutcome], None] | None = None  # called with each finished episode record
    should_stop: Callable[[], bool] | None = None  # True once the run is asked to stop (SIGINT/SIGTERM)
    log: Callable[[str], None] | None = None  # phase log of episode 0 (one line per phase)
    sink: EpisodeSink | None = None  # a dataset sink (``robocfg.datasets.sink.DatasetSink``) recording every episode
    resumed: tuple[Any, ...] = ()  # records of episodes an interrupted run finished: not run again, reported
    # time every physics step (World.time_physics): BatchTiming.physics_per_episode, for benchmarks; off, it reads 0
    time_physics: bool = False

    def resolved_seed(self, task_seed: int) -> int:
        return task_seed if self.seed is None else self.seed

    def portable(self) -> RunOptions:
        """A copy without the in-process hooks (callbacks, recorder factory, sink): picklable."""
        return dataclasses.replace(self, recorder=None, on_episode=None, should_stop=None, log=None, sink=None,
                                   resumed=())

    def stop_requested(self) -> bool:
        return self.should_stop is not None and bool(self.should_stop())


@dataclass(frozen=True)
class OptionSpec:
    """How a field of a kind's ``Options`` dataclass appears on the command line."""

    flags: tuple[str, ...]  # e.g. ("--plot",) or ("--with-obstacle/--without-obstacle",)
    help: str
    output_suffixes: tuple[str, ...] = ()  # an output file: checked before simulating, must end so
    choices: tuple[str, ...] = ()  # allowed values of a str option
    minimum: float | None = None  # smallest allowed value of a number option


def option(*flags: str, help: str, output: tuple[str, ...] = (), choices: tuple[str, ...] = (),
           minimum: float | None = None) -> dict[str, Any]:
    """The metadata of a field of a kind's ``Options``: its command-line flag(s) and help, e.g.
    ``plot: Path | None = field(default=None, metadata=option("--plot", help="..."))``."""
    return {"robocfg": OptionSpec(tuple(flags), help, tuple(output), tuple(choices), minimum)}


def option_spec(f: dataclasses.Field) -> OptionSpec:
    spec = f.metadata.get("robocfg")
    if not isinstance(spec, OptionSpec):
        raise TypeError(f"field {f.name!r} of a kind's Options needs option(...) (its flag and help)")
    return spec
