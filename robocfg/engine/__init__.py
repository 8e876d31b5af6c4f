"""The episode engine: one place where a task's episodes are set up, stepped, observed, recorded
and reported, and the task registry that maps a ``task:`` kind to its runner.

Per-episode API (what the executors, the data engine and the Gym environments call)::

    from robocfg.engine import EpisodeSpec, RunOptions, open_session, run_episode

    options = RunOptions(seed=7)
    with open_session(task, options) as session:    # world built once per process
        record = session.run(3)                    # episode 3: rng = default_rng([7, 3])

    record = run_episode(EpisodeSpec.of(task, 3, options))   # the same record, anywhere

A batch run (``robocfg run pick-place -n 200``) is ``session.run(k)`` for k = 0..199, so the
record of episode k is the same whether it ran in a batch, alone, or in another process.

Modules: ``options`` (:class:`RunOptions`, a kind's own ``option(...)`` fields), ``runner``
(the :class:`TaskRunner` protocol and the report view), ``registry`` (``@register_task``,
``runner_for``), ``session`` (:class:`EpisodeSession`: world build, snapshot/restore, episode
rng, recording hook, timing; :func:`run_batch`), ``randomize`` (the seeded body randomisation
every kind shares), ``spec`` (:class:`EpisodeSpec`, :func:`run_episode`, :func:`open_session`),
``records`` (episode records read back from a ``--json`` report, for ``--resume``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from robocfg.engine.options import EpisodeObserver, RunOptions, option
    from robocfg.engine.registry import register_task, registered, runner_for
    from robocfg.engine.runner import ReportView, RunOutput, TableView, TaskCommand, TaskRunner
    from robocfg.engine.session import (
        BatchTiming,
        EpisodeSession,
        EpisodicRunner,
        Session,
        episode_rng,
        run_batch,
    )
    from robocfg.engine.spec import EpisodeSpec, TaskSource, open_session, run_episode

__all__ = ["BatchTiming", "EpisodeObserver", "EpisodeSession", "EpisodeSpec", "EpisodicRunner", "ReportView",
           "RunOptions", "RunOutput", "Session", "TableView", "TaskCommand", "TaskRunner", "TaskSource", "episode_rng",
           "open_session", "option", "register_task", "registered", "run", "run_batch", "run_episode", "runner_for"]

# name → the module that defines it. Loaded on first use (PEP 562), so importing one light module
# of the package (``robocfg.engine.options``, ``robocfg.engine.dataset``: a kind's command-line
# options) does not load the registry, every kind's config models and the session machinery — what
# ``robocfg run KIND --help`` would otherwise pay (≈ 0.1 s).
_LAZY = {
    **dict.fromkeys(("EpisodeObserver", "RunOptions", "option"), "options"),
    **dict.fromkeys(("register_task", "registered", "runner_for"), "registry"),
    **dict.fromkeys(("ReportView", "RunOutput", "TableView", "TaskCommand", "TaskRunner"), "runner"),
    **dict.fromkeys(("BatchTiming", "EpisodeSession", "EpisodicRunner", "Session", "episode_rng", "run_batch"),
                    "session"),
    **dict.fromkeys(("EpisodeSpec", "TaskSource", "open_session", "run_episode"), "spec"),
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'robocfg.engine' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"robocfg.engine.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def run(task: Any, options: RunOptions | None = None) -> RunOutput:
    """Run a checked task of any kind; its :class:`RunOutput` (report + timing)."""
    from robocfg.engine.registry import runner_for

    runner = runner_for(task.config.task)(task, options)
    runner.check()
    return runner.run()
