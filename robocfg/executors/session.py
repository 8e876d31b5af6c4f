"""What an executor distributes, and what runs in each worker.

An executor never simulates. It receives a *recipe* (picklable: the task's source and the run
options, no world, no open file) and episode indices. Each worker process opens the recipe once
into a *session* (builds the world, kinematics and controllers once), then runs the episodes
it is given with ``session.run(k, sink)``. Episode k draws its randomness from
``numpy.random.default_rng([seed, k])``, so its record is the same in whichever worker, in
whichever order, it runs. Episodes are handed out in *batches*; a batch is the unit that is
committed: its records come back together with the dataset shard its episodes were written to,
and a worker that dies takes exactly its unfinished batch with it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from robocfg.datasets.files import FileLimits

if TYPE_CHECKING:
    from robocfg.datasets.episode import Actions
    from robocfg.datasets.shards import Shard
    from robocfg.datasets.sink import DatasetSink, Format, Keep
    from robocfg.executors.usage import Usage
    from robocfg.executors.worker_setup import SetupDone
    from robocfg.sim.camera_rig import Renderer


class EpisodeRecord(Protocol):
    """The fields of an episode's record the executors read (the progress bar counts successes)."""

    index: int
    success: bool


class Session(Protocol):
    """A worker's built world for one task: runs episode ``k`` (recording into ``sink`` when one
    is given) and returns its :class:`EpisodeRun`; ``report`` makes the run's report from the
    records of every finished episode (in index order). ``task``: the checked task."""

    task: Any

    def run(self, k: int, sink: DatasetSink | None = None) -> EpisodeRun: ...

    def report(self, records: list[Any], interrupted: bool) -> Any: ...

    def close(self) -> None: ...


class Recipe(Protocol):
    """Picklable description of a run that a worker opens into a :class:`Session`.

    ``preload``: modules a worker imports before it is handed anything (a process pool imports them
    once in its fork server, so each worker starts without paying the imports again)."""

    @property
    def episodes(self) -> int: ...

    @property
    def dataset(self) -> DatasetTarget | None: ...

    @property
    def preload(self) -> tuple[str, ...]: ...

    def open(self) -> Session: ...


@dataclass(frozen=True)
class EpisodeRun:
    """One finished episode: its record (the report's entry), wall time (s) and the part of it spent
    stepping the physics (s); ``cpu``: the worker process's CPU time over the episode (s, user +
    system, every thread: a Ray actor's own threads included), ``thread_cpu``: the part on the
    thread that ran it (s). CPU times do not count time spent waiting for a core, so they compare
    executors on a loaded machine where wall times do not. ``usage``: the process's resource use
    over the episode (user and system CPU, page faults, context switches; None where not taken)."""

    record: Any
    wall: float
    physics: float
    cpu: float = 0.0
    thread_cpu: float = 0.0
    usage: Usage | None = None

    @property
    def index(self) -> int:
        return int(self.record.index)

    @property
    def success(self) -> bool:
        return bool(self.record.success)


@dataclass(frozen=True)
class DatasetTarget:
    """Where and how a run's episodes are recorded: the dataset folder, format, frame rate (Hz), which episodes are kept, the language string and the run facts stored in the
    dataset's metadata. Workers write shards under ``<root>/.shards/``; the driver merges them
    into ``root``."""

    root: Path
    fmt: Format
    fps: int
    keep: Keep
    language: str
    extra_info: dict = field(default_factory=dict)
    renderer: Renderer = "auto"  # camera images (robocfg.sim.camera_rig)
    actions: Actions = "joint"  # which actions are stored (--dataset-actions)
    limits: FileLimits = field(default_factory=FileLimits)  # when LeRobot files roll over (shards and the merge)

    def shard_root(self, batch: int) -> Path:
        return Path(self.root) / ".shards" / f"batch-{batch:05d}"

    def sink(self, task: Any, root: Path) -> DatasetSink:
        from robocfg.datasets.sink import DatasetSink

        return DatasetSink(root, self.fmt, task, fps=self.fps, keep=self.keep, language=self.language,
                           extra_info=dict(self.extra_info), renderer=self.renderer, actions=self.actions,
                           limits=self.limits)


@dataclass(frozen=True)
class Batch:
    """Episode indices run one after the other by one worker; ``id`` numbers its shard."""

    id: int
    indices: tuple[int, ...]


@dataclass
class BatchDone:
    """A committed batch: its episodes' runs in index order and the shard they were recorded to;
    ``pid``: the worker process that ran it, ``cpu``: that process's CPU time (s, all threads) when
    the batch began and when it ended (a benchmark sums a worker's CPU between batches from them);
    ``wall``: the wall clock (s since the epoch) when it began and ended in the worker (a
    benchmark places the batches on one time line with the driver's: the gaps between them)."""

    batch: Batch
    runs: list[EpisodeRun]
    shard: Shard | None
    pid: int = 0
    cpu: tuple[float, float] = (0.0, 0.0)
    wall: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class WorkerStart:
    """When a worker started (wall clock, s since the epoch): its process was created
    (``created``), it began opening the recipe (``opening``: the interpreter, its imports and the
    recipe's unpickling done) and its session was open (``ready``: world, model and controllers
    built); ``niceness``: its scheduling niceness (a higher one yields the CPU to other processes);
    ``threads``: the process's threads then (0: unknown); ``math_threads``: the most threads a math
    library loaded in it may use (0: none found; :func:`robocfg.executors.worker_setup.math_threads`);
    ``setup``: what a pool worker did to its process first (:mod:`robocfg.executors.worker_setup`;
    None: nothing, as in a Ray actor)."""

    pid: int
    created: float
    opening: float
    ready: float
    niceness: int = 0
    threads: int = 0
    setup: SetupDone | None = None
    math_threads: int = 0


def worker_start(opening: float, setup: SetupDone | None = None) -> WorkerStart:
    """This process's :class:`WorkerStart`, its session having opened just now."""
    import os
    import time

    from robocfg.executors.usage import thread_count
    from robocfg.executors.worker_setup import math_threads

    return WorkerStart(os.getpid(), _created(), opening, time.time(), os.nice(0), thread_count(), setup,
                       math_threads())


def _created() -> float:
    """When this process was created (s since the epoch, 10 ms steps; Linux ``/proc``; NaN elsewhere)."""
    import os
    import time

    try:
        with open("/proc/self/stat") as f:
            ticks = int(f.read().rsplit(")", 1)[1].split()[19])  # field 22: start time in clock ticks
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])  # s since boot, 10 ms steps
        return time.time() - uptime + ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return float("nan")


@dataclass(frozen=True)
class ReportRequest:
    """Sent to one worker at the end: make the run's report from these records (index order)."""

    records: list[Any]
    interrupted: bool


def plan_batches(episodes: int, workers: int, recording: bool) -> list[Batch]:
    """Consecutive index ranges, handed out in order to whichever worker is free. Without a dataset
    a batch is one episode (a crash loses one). With one, up to 8 episodes share a shard (fewer files
    to merge), in batches that shrink as the run goes (guided self-scheduling: a batch is the
    remaining episodes ÷ 2 × workers, rounded up, at most 8), so the last batches are single
    episodes and the workers finish within about one episode of each other — a fixed size left a
    worker up to a quarter of its share behind the others. Which episodes share a shard does not
    change the merged dataset."""
    w = max(1, workers)
    batches: list[Batch] = []
    a = 0
    while a < episodes:
        size = 1 if not recording else max(1, min(8, -(-(episodes - a) // (2 * w))))
        batches.append(Batch(len(batches), tuple(range(a, min(a + size, episodes)))))
        a += size
    return batches


def run_batch(session: Session, dataset: DatasetTarget | None, batch: Batch,
              on_episode: Callable[[EpisodeRun], None] | None = None) -> BatchDone:
    """Run ``batch`` in ``session``; with a dataset, record it into the batch's shard and close it.

    The dataset modules are imported only with a dataset: a run without one never loads them (they
    import scipy.spatial among others: 0.3–0.5 s on the 2-core laptop, which a Ray actor, not
    forked from a preloaded server, paid inside its first batch)."""
    import os
    import time

    wall0, cpu0 = time.time(), time.process_time()
    sink = dataset.sink(session.task, dataset.shard_root(batch.id)) if dataset is not None else None
    runs = []
    for k in batch.indices:
        run = session.run(k, sink)
        runs.append(run)
        if on_episode is not None:
            on_episode(run)
    shard = None
    if sink is not None:
        from robocfg.datasets.shards import close_shard

        shard = close_shard(sink)
    return BatchDone(batch, runs, shard, os.getpid(), (cpu0, time.process_time()), (wall0, time.time()))


def report_in_driver(recipe: Recipe, records: list[Any], interrupted: bool) -> Any:
    """The run's report from a session opened here: when no worker is left to make it."""
    session = recipe.open()
    try:
        return session.report(records, interrupted)
    finally:
        session.close()
