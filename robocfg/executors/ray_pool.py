"""``--executor ray``: the same batches as ``--workers``, run by Ray actors (one CPU each).

Each actor opens the recipe once (its world lives as long as the actor) and runs the batches it
is given as actor calls; the driver keeps ``IN_FLIGHT`` calls queued per actor (an actor runs
them in order, so it starts its next batch without waiting for the driver to collect the last
one and send another) and hands the next batch to whichever actor returns. Dataset shards are written by the actors under the dataset
folder, so on a cluster that folder must be on a filesystem every node shares (see
``docs/scale-out.md``); the driver merges them. An actor that dies (node lost, process killed)
surfaces as ``RayActorError`` on its calls: those batches are reported lost and the others go on.

Kept actors (``RayPool(..., keep=True)``, for a process that makes several runs on one Ray: a
notebook, a service, a benchmark): after a run its actors are not ended but keep their process,
with robocfg imported, and close their session; the next kept run in this process reopens its
recipe in them, so its start is the world build alone — as a process pool's worker forks from a
fork server that has imported robocfg once — instead of a new interpreter per actor. Idle kept
actors hold their CPU in Ray; :func:`release_kept` ends them (a Ray shut down by robocfg ends them
too). The CLI, one run per process, does not keep actors.

Where Ray runs: ``address`` (``--ray-address``), else ``RAY_ADDRESS``, else a local Ray started
here and shut down after the run. A Ray already initialised in this process (a test, a notebook)
is used as it is.

Priority: Ray starts its worker processes at niceness 15 (its ``worker_niceness`` setting), so
an actor yields its core to any ordinary process — on a shared host, or beside a process pool,
it ran at a fraction of a pool worker's speed for the same CPU time per episode. A local Ray
started here runs its workers at the driver's niceness (``worker_niceness`` 0), as a pool's
workers run; a cluster started by ``ray start`` keeps its own setting (``RAY_worker_niceness=0``
in the environment of ``ray start`` gives the same; ``docs/scale-out.md``).
"""

from __future__ import annotations

import importlib
import logging
import os
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from robocfg.errors import RobocfgError
from robocfg.executors.outcome import Execution, LostEpisodes
from robocfg.executors.pool import POLL, WorkerError
from robocfg.executors.session import (
    Batch,
    BatchDone,
    EpisodeRun,
    Recipe,
    WorkerStart,
    report_in_driver,
    run_batch,
    worker_start,
)

IN_FLIGHT = 2  # actor calls queued per actor: it never waits for the driver between batches
WORKER_NICENESS = 0  # niceness increment of a local Ray's workers (Ray's own default: 15)


@dataclass
class _Kept:
    """Actors that ``RayPool(keep=True)`` runs left alive, their sessions closed, for the next such
    run in this process while the same Ray job (``job``) runs."""

    job: str | None = None
    actors: list[Any] = field(default_factory=list)


_KEPT = _Kept()


class _Actor:
    """A Ray actor holding one session (opened from a recipe; reopened for another by ``open``)."""

    def __init__(self, recipe: Recipe):
        from robocfg import collector
        from robocfg.executors.worker_setup import follow_omp_threads

        collector.pause()  # until its world is built (robocfg.collector)
        follow_omp_threads()  # one math-library thread, as a pool worker runs (worker_setup)
        self.session: Any = None
        self.open(recipe)

    def open(self, recipe: Recipe) -> WorkerStart:
        """Close the session this actor holds, if any, and open ``recipe``'s."""
        opening = time.time()
        self.close()
        for module in recipe.preload:  # what a pool's fork server imports: here, in the actor's start
            importlib.import_module(module)
        self.recipe = recipe
        self.session = recipe.open()
        self.start = worker_start(opening)
        return self.start

    def close(self) -> None:
        if self.session is not None:
            self.session.close()
            self.session = None

    def pid(self) -> int:
        return os.getpid()

    def started(self) -> WorkerStart:
        return self.start

    def run(self, batch: Batch) -> BatchDone:
        return run_batch(self.session, self.recipe.dataset, batch)

    def report(self, records: list[Any], interrupted: bool) -> Any:
        return self.session.report(records, interrupted)


class RayPool:
    """Run a recipe's episodes on ``workers`` Ray actors (see the module docstring)."""

    def __init__(self, workers: int, address: str | None = None, keep: bool = False):
        if workers < 1:
            raise RobocfgError(f"--workers {workers}: need at least 1")
        self.workers, self.address, self.keep = workers, address, keep
        self.actors: list[Any] = []
        self.starts: list[WorkerStart] = []  # how each actor started, filled by start()
        self._started: tuple[Recipe, bool] | None = None  # the actors' recipe, and whether Ray was started here

    def start(self, recipe: Recipe) -> None:
        """Start the actors for ``recipe`` and wait until each has built its world: the fixed start
        of a run (a fresh interpreter per actor), which the next :meth:`run` of the same recipe then
        skips (a benchmark times it apart from the episodes). Optional: ``run`` starts them itself."""
        ray = _ray()
        from ray.exceptions import RayActorError

        started = _init(ray, self.address)
        self._start_actors(ray, recipe, self.workers)
        self._started = (recipe, started)
        try:
            self.starts = ray.get([a.started.remote() for a in self.actors])
        except RayActorError as exc:
            self._started = None
            self._stop(ray, started)
            raise WorkerError(f"a Ray actor could not start: {_first_line(exc)}") from exc

    def _start_actors(self, ray: Any, recipe: Recipe, count: int) -> None:
        """``count`` actors holding ``recipe``'s session: with ``keep``, idle kept actors first (each
        reopens its session; one that died meanwhile is replaced), new ones for the rest."""
        from ray.exceptions import RayActorError

        remote = ray.remote(num_cpus=1, max_restarts=0)(_Actor)
        job = ray.get_runtime_context().get_job_id()
        if job != _KEPT.job:  # kept under another Ray (shut down and started again): gone with it
            _KEPT.job, _KEPT.actors = job, []
        reused = [_KEPT.actors.pop() for _ in range(min(count, len(_KEPT.actors)))] if self.keep else []
        opened = [a.open.remote(recipe) for a in reused]
        self.actors = [remote.remote(recipe) for _ in range(count - len(reused))]
        for a, ref in zip(reused, opened, strict=True):
            try:
                ray.get(ref)
                self.actors.append(a)
            except RayActorError:
                self.actors.append(remote.remote(recipe))

    def _stop(self, ray: Any, shutdown: bool, keep: bool = False) -> None:
        """End the actors (with ``keep``: close their sessions and keep them for the next kept run),
        and shut Ray down when it was started here."""
        if keep and not shutdown:
            for a in self.actors:
                a.close.remote()
            _KEPT.actors.extend(self.actors)
        else:
            for a in self.actors:
                ray.kill(a)
        self.actors = []
        if shutdown:
            release_kept(ray)
            ray.shutdown()

    def run(self, recipe: Recipe, batches: list[Batch], on_episode: Callable[[EpisodeRun], None] | None = None,
            should_stop: Callable[[], bool] | None = None) -> Execution:
        """Run ``batches`` on the actors :meth:`start` started for this recipe, else on new ones
        (one per worker, each kept for all the batches); the actors end when it returns (with
        ``keep``, after a run that lost no episode, they stay, idle, for the next kept run)."""
        ray = _ray()
        from ray.exceptions import RayActorError, RayTaskError

        prior, self._started = self._started, None
        if prior is not None and prior[0] is not recipe:
            self._stop(ray, prior[1])
            prior = None
        if prior is not None:
            started = prior[1]
            result = Execution(workers=len(self.actors))
        else:
            started = _init(ray, self.address)
            result = Execution(workers=min(self.workers, len(batches)) or 1)
            self._start_actors(ray, recipe, result.workers)
        todo = deque(batches)
        inflight: dict[Any, tuple[Any, Batch]] = {}
        kept = False  # the actors go back to the kept ones only after a run that lost none

        def hand_out(actor: Any) -> None:
            if todo:
                batch = todo.popleft()
                inflight[actor.run.remote(batch)] = (actor, batch)

        try:
            for _ in range(IN_FLIGHT):
                for a in self.actors:
                    hand_out(a)
            while inflight:
                if should_stop is not None and should_stop() and todo:
                    result.interrupted = True
                    todo.clear()
                ready, _ = ray.wait(list(inflight), num_returns=1, timeout=POLL)
                for ref in ready:
                    actor, batch = inflight.pop(ref)
                    try:
                        done: BatchDone = ray.get(ref)
                    except RayActorError as exc:
                        result.lost.append(LostEpisodes(batch.indices, f"Ray actor died: {_first_line(exc)}"))
                        continue
                    except RayTaskError as exc:
                        raise WorkerError(f"a Ray worker failed: {_first_line(exc)}") from exc
                    result.done.append(done)
                    if on_episode is not None:
                        for run in done.runs:
                            on_episode(run)
                    hand_out(actor)
            for batch in todo:
                result.lost.append(LostEpisodes(batch.indices, "no Ray actor left to run it"))
            result.report = _report_of(ray, self.actors, recipe, result)
            kept = self.keep and not result.lost
        finally:
            self._stop(ray, started, keep=kept)
        return result


def release_kept(ray: Any) -> None:
    """End the actors that ``RayPool(keep=True)`` runs kept (they hold a CPU each while idle)."""
    while _KEPT.actors:
        ray.kill(_KEPT.actors.pop())


def _ray() -> Any:
    try:
        import ray
    except ImportError as exc:
        raise RobocfgError("--executor ray needs Ray: pip install 'robocfg[ray]'") from exc
    return ray


def _init(ray: Any, address: str | None) -> bool:
    """Connect to Ray unless this process already is; True when Ray was started here (and is to be
    shut down after the run)."""
    if ray.is_initialized():
        return False
    init_ray(ray, address or os.environ.get("RAY_ADDRESS") or None)
    return True


def init_ray(ray: Any, address: str | None = None, num_cpus: int | None = None) -> None:
    """``ray.init`` as ``--executor ray`` calls it: no dashboard, workers' logs not copied to the
    driver; with no ``address`` a local Ray (``num_cpus`` CPUs, default all) whose workers run at
    the driver's niceness (:data:`WORKER_NICENESS`; see the module docstring)."""
    kwargs: dict[str, Any] = {}
    if address in (None, "local"):  # a new Ray on this machine (Ray's own reading of "local")
        kwargs = {"num_cpus": num_cpus, "_system_config": {"worker_niceness": WORKER_NICENESS}}
    ray.init(address=address, include_dashboard=False, logging_level=logging.ERROR, log_to_driver=False, **kwargs)


def _report_of(ray: Any, actors: list[Any], recipe: Recipe, result: Execution) -> Any:
    """The run's report from the first actor that answers; with none left, from a session here."""
    from ray.exceptions import RayActorError

    for a in actors:
        try:
            return ray.get(a.report.remote(result.records, result.interrupted))
        except RayActorError:
            continue
    return report_in_driver(recipe, result.records, result.interrupted)


def _first_line(exc: BaseException) -> str:
    lines = [ln for ln in str(exc).splitlines() if ln.strip()]
    return lines[0] if lines else type(exc).__name__
