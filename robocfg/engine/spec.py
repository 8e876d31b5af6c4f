"""Episodes described as data: a picklable :class:`EpisodeSpec` runs anywhere with the same result.

``EpisodeSpec(task, seed, index, options)`` names episode ``index`` of a run seeded ``seed``;
:func:`run_episode` gives exactly the record that episode gets inside a batch run of the same
task, seed and options, in any process and order. :func:`open_session` is the per-process
session an executor builds once and then calls ``session.run(k)`` on for many k.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robocfg.engine.options import RunOptions

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.config.load import YamlDocument
    from robocfg.engine.session import Session


@dataclass(frozen=True)
class TaskSource:
    """A task as data that can travel to another process: the task document as validated (robot
    override and dotted-key overrides already applied); ``load()`` checks it again there.
    ``written_robot``: the robot YAML the file itself names (before ``--robot``), which the
    document no longer says and ``placement: auto`` scales from."""

    doc: YamlDocument
    written_robot: Path | None = None

    @classmethod
    def of(cls, task: CheckedTask) -> TaskSource:
        return cls(task.doc, task.written_robot)

    @classmethod
    def from_path(cls, path: str | Path, robot: str | None = None,
                  overrides: Mapping[str, Any] | None = None) -> TaskSource:
        from robocfg.checks.task import load_task

        return cls.of(load_task(path, robot_override=robot, overrides=overrides))

    def load(self) -> CheckedTask:
        from robocfg.checks.task import check_task_document

        task = check_task_document(self.doc)
        if self.written_robot is not None:
            task.written_robot = self.written_robot
        return task


@dataclass(frozen=True)
class EpisodeSpec:
    """Episode ``index`` of a run of ``task`` seeded ``seed`` with ``options`` (picklable: the
    options travel without their in-process callbacks)."""

    task: TaskSource
    seed: int
    index: int
    options: RunOptions = field(default_factory=RunOptions)

    @classmethod
    def of(cls, task: CheckedTask, index: int, options: RunOptions | None = None) -> EpisodeSpec:
        o = (options or RunOptions()).portable()
        seed = o.resolved_seed(task.config.sim.seed)
        return cls(TaskSource.of(task), seed, index, dataclasses.replace(o, seed=seed))

    def session_options(self) -> RunOptions:
        return dataclasses.replace(self.options.portable(), seed=self.seed,
                                   episodes=max(self.options.episodes, self.index + 1))


def open_session(task: CheckedTask, options: RunOptions | None = None) -> Session:
    """The per-process session of a checked task (the caller closes it): ``session.run(k)``."""
    from robocfg.engine.registry import runner_for

    runner = runner_for(task.config.task)(task, options)
    runner.check()
    return runner.open_session()


@dataclass
class _Cache:
    """The session kept by :func:`run_episode` for the next spec of the same run."""

    key: tuple[str, str, RunOptions] | None = None
    session: Session | None = None


_cache = _Cache()


def run_episode(spec: EpisodeSpec) -> Any:
    """Episode ``spec.index``'s record, identical to the one a batch run records for it.

    The session is kept for the next call with the same task and options (a worker running many
    specs of one run builds its world once); another task or options closes it first."""
    options = spec.session_options()
    key = (str(spec.task.doc.path), repr(spec.task.doc.data), dataclasses.replace(options, episodes=1))
    if _cache.session is None or _cache.key != key:
        close_cached_session()
        _cache.session, _cache.key = open_session(spec.task.load(), options), key
    return _cache.session.run(spec.index)


def close_cached_session() -> None:
    """Close the session :func:`run_episode` keeps (tests, or a worker before it exits)."""
    if _cache.session is not None:
        _cache.session.close()
    _cache.session, _cache.key = None, None
