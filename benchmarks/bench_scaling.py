"""Pick-place episodes/s on 1, 2, 4 ... N worker processes, and Ray actors next to them, in
interleaved rounds.

    python benchmarks/bench_scaling.py [--workers 1,2,4,8,16] [--per-worker 16] [--rounds 5] [--ray]
                                       [--ray-kept] [--pool-variants single,default,pin,malloc]
                                       [--dataset] [--no-in-process] [--json out.json]

Weak scaling: a run of worker count w runs ``per-worker × w`` episodes of the shipped pick-place task
without cameras (seed 0) through the executors the CLI uses (``--workers``: a process pool;
``--ray``: Ray actors on a local Ray started once, before any timing, as ``--executor ray`` starts
one — workers at the driver's niceness — with ``num_cpus`` = the largest worker count, twice that
with ``--ray-kept``; ``--ray-worker-niceness 15`` gives Ray's own default; ``--ray-kept``: Ray
actors kept from one run to the next, ``RayPool(keep=True)``, so a run's start is the world build
in a process that has robocfg imported, as a pool worker's is). Each round runs, for every worker
count, the pool and Ray one after the other, who goes first rotating from round to round (A B, B A,
A B ...; A B C, B C A, C A B ... with three), so slow drifts of a shared host's load fall on all
alike; every figure is a median over the rounds, with its spread (min–max), and Ray ÷ pool is taken
within each round (paired) before its median.

What a run measures, each part apart:

* *start*: the pool's ``start()`` — workers started until every one has built its world — split
  into *boot* (asked → the worker begins opening the recipe: process creation, interpreter,
  imports, unpickling; a pool worker forks from a fork server that has imported robocfg, a Ray
  actor is a fresh interpreter, a kept one the process of an earlier run: *spawn* < 0) and *build* (world, kinematic model, controllers), medians over
  the workers;
* *steady*: the episodes on those workers, ``episodes / run s``; *run s* is ``run()`` from its
  call to its return on the started workers — handing the batches out, the episodes, collecting
  the results, the run's report (made by one worker from every record) and stopping the workers —
  plus, with ``--dataset``, merging the shards;
* *where the workers' time went* (``workers × run s`` split, from wall-clock stamps each batch
  carries from its worker, ``BatchDone.wall``): inside episodes; *lead* (``run()`` called → the
  worker's first batch begins); inside batches outside episodes; *gaps* between one batch's end and
  the next one's start on a worker (the executor's round trip per batch); *imbalance* (a worker idle
  after its last batch while others finish: the tail); *end* (the last batch → ``run()`` returned:
  report, stop). *Had core*: CPU ÷ wall inside episodes (< 100 %: the worker waited for a core);
* efficiency and Ray ÷ pool as products of three factors (each a median over the rounds):
  *cpu* (CPU per episode: cores that run slower when all are busy, shared caches), *core* (the
  share of episode time a worker had a core: other processes on the cores) and *busy* (the share
  of worker-seconds spent in episodes: lead, gaps, tail, end);
* *CPU per episode*, robust to a host's load because waiting for a core costs no CPU time:
  ``episode ms`` — the worker process's CPU time over one episode (every thread), median over
  every episode of every round (``1st ms``: each worker's first episode, which pays what the
  worker imports or builds lazily); ``worker ms/ep`` — the workers' CPU from their first batch's start
  to their last batch's end ÷ episodes (adds what runs between episodes: receiving a batch,
  returning a result, an executor's own threads); ``driver+ ms/ep`` — the CPU of the driver and of
  every other process it started (fork server; Ray's raylet, GCS, agents and idle workers) during
  the run ÷ episodes (needs psutil). ``cpu ms/ep`` is their sum: the machine's CPU per episode.

``--pool-variants``: the pool with other worker set-ups (math-library threads as the libraries'
default, pinned workers, glibc malloc settings) as further executors in the same rounds, and what
an episode costs its process at each worker count (main thread vs process CPU, user vs system,
page faults, context switches, the machine's steal time): ``benchmarks/_scaling_usage.py`` says
what each column means.

*Core speed* (printed first): a fixed pure-Python loop's CPU time alone ÷ with w copies at once
— what the machine's cores give when w of them are busy (turbo limits, shared caches), the part of
the *cpu* factor below that no executor can change; *memory speed*: the same for sums over a
32 MiB array (memory bandwidth per core with w busy); *physics speed*: the same for 1000 bare
physics steps of the task's world at rest (the engine alone, no robocfg code around it).

Before each run the benchmark waits (up to 10 s, printed) until the processes under it use under
half a core: the previous run's workers leaving and Ray starting idle workers to replace killed
actors' processes would otherwise fall into the next run's timing.

Efficiency = steady pool throughput at w ÷ (w × the 1-worker pool's), per round. ``rounds ±5 %`` is
how many rounds bound the median of a paired ratio to about ±5 % at 95 % (``(2 s / 0.05)²``, ``s``
the standard deviation of the ratio's logarithm over the rounds), for the wall ratio and for the
episode-CPU ratio: the goal "Ray within 10 %" is shown only where that is no more than the rounds
run. ``n for +start ≥ 0.9``: episodes per worker from which Ray with its start reaches 0.9 × the
pool with its (from the median starts and steady rates). The first row (unless
``--no-in-process``) is the same episodes once in the calling process, world build included.
"""

from __future__ import annotations

import argparse
import functools
import itertools
import json
import math
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from _scaling_usage import CpuTimes, pool_kinds, setup_of, usage_table, variant_table

RAY_KINDS = ("ray", "ray-kept")  # Ray actors started for each run (as the CLI does), kept actors reused
POOL_KINDS = ("pool", "pool-default", "pool-pin", "pool-malloc")  # --pool-variants (_scaling_usage)


@dataclass
class Sample:
    """One run of one executor at one worker count (times in s, CPU in s)."""

    executor: str
    workers: int
    round: int
    episodes: int
    start_s: float
    run_s: float
    successes: int
    boot_s: float = float("nan")  # median over workers: asked -> opening the recipe
    spawn_s: float = float("nan")  # median over workers: asked -> process created (< 0: a prestarted process)
    build_s: float = float("nan")  # median over workers: opening -> session open
    episode_cpu: list[float] = field(default_factory=list)  # per episode, worker process CPU
    episode_thread_cpu: list[float] = field(default_factory=list)  # per episode, the running thread's CPU
    worker_cpu: float = 0.0  # all workers, first batch start -> last batch end
    others_cpu: float = float("nan")  # driver + every other process it started, during the run
    first_cpu: float = float("nan")  # median over workers: CPU of each worker's first episode
    niceness: list[int] = field(default_factory=list)  # the workers' scheduling niceness
    time_line: TimeLine | None = None  # where the run's worker-seconds went
    first_thread_cpu: float = float("nan")  # the same, the episode's thread only
    usage: list = field(default_factory=list)  # per episode: robocfg.executors.usage.Usage (None: not taken)
    threads: list[int] = field(default_factory=list)  # each worker's threads once its world was built
    math_threads: list[int] = field(default_factory=list)  # each worker's math-library thread count then
    episode_wall: list[float] = field(default_factory=list)  # per episode, wall time (s)
    episode_physics: list[float] = field(default_factory=list)  # per episode, wall time inside stepSimulation (s)
    steal_pct: float = float("nan")  # the machine's steal time over the run, % of all CPUs' time
    busy_pct: float = float("nan")  # the machine's non-idle time over the run, % of all CPUs' time

    @property
    def eps(self) -> float:
        return self.episodes / self.run_s

    @property
    def eps_with_start(self) -> float:
        return self.episodes / (self.run_s + self.start_s)

    @property
    def cpu_per_episode(self) -> float:
        return (self.worker_cpu + self.others_cpu) / self.episodes


@dataclass(frozen=True)
class TimeLine:
    """Where a run's ``workers × run s`` worker-seconds went (s, summed over the workers), from the
    wall-clock stamps each batch carries (``BatchDone.wall``, taken in the worker) and the driver's
    own around ``run()``: ``lead`` — run called → the worker's first batch begins (handing out,
    the first call's delivery, anything the worker does before its first batch); ``episodes`` —
    inside episodes (``EpisodeRun.wall``); ``batch`` — inside batches, outside episodes (a shard's
    opening and closing, the result's assembly); ``gaps`` — between one batch's end and the next
    one's start on the same worker (returning a result, receiving the next batch: an executor's
    round trip); ``imbalance`` — the worker's last batch end → the last batch end of all (the
    tail: idle while others finish); ``end`` — the last batch end of all → ``run()`` returned
    (the report, made by one worker from every record, and stopping the workers), counted for
    every worker. ``episode_cpu``: CPU inside the episodes (s): ÷ ``episodes`` is the share of
    the episodes' wall time the workers had a core."""

    lead: float
    episodes: float
    batch: float
    gaps: float
    imbalance: float
    end: float
    episode_cpu: float
    n_gaps: int = 0  # how many gaps ``gaps`` sums

    @classmethod
    def of(cls, done: list, called: float, returned: float, workers: int) -> TimeLine:
        by_worker: dict[int, list] = {}
        for b in sorted(done, key=lambda b: b.wall[0]):
            by_worker.setdefault(b.pid, []).append(b)
        last = max(bs[-1].wall[1] for bs in by_worker.values())
        episodes = sum(r.wall for b in done for r in b.runs)
        spans = sum(b.wall[1] - b.wall[0] for b in done)
        return cls(lead=sum(bs[0].wall[0] - called for bs in by_worker.values()),
                   episodes=episodes, batch=spans - episodes,
                   gaps=sum(n.wall[0] - p.wall[1] for bs in by_worker.values() for p, n in itertools.pairwise(bs)),
                   n_gaps=sum(len(bs) - 1 for bs in by_worker.values()),
                   imbalance=sum(last - bs[-1].wall[1] for bs in by_worker.values()),
                   end=workers * (returned - last), episode_cpu=sum(r.cpu for b in done for r in b.runs))

    @property
    def total(self) -> float:
        return self.lead + self.episodes + self.batch + self.gaps + self.imbalance + self.end


def _task_without_cameras(tmp: Path) -> Path:
    import yaml

    from robocfg.config import catalog

    doc = yaml.safe_load(Path(catalog.find("tasks", "pick_place")).read_text())
    doc.pop("cameras", None)
    path = tmp / "pick_place_state_only.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _target(root: Path | None, task):
    if root is None:
        return None
    from robocfg.datasets.language import pick_place_instruction
    from robocfg.executors.session import DatasetTarget

    return DatasetTarget(root, "lerobot", 20, "success", pick_place_instruction(task.config.pick_place),
                         {"task_path": str(task.path), "seed": 0})


class TreeCpu:
    """CPU time (s, user + system) of this process and every process under it, except ``skip``:
    sampled by :meth:`snapshot`; processes that end between two snapshots are missed."""

    def __init__(self) -> None:
        try:
            import psutil
        except ImportError:
            self.psutil = None
        else:
            self.psutil = psutil

    def snapshot(self, skip: set[int]) -> dict[int, float]:
        if self.psutil is None:
            return {}
        me = self.psutil.Process()
        out = {}
        for p in [me, *me.children(recursive=True)]:
            if p.pid in skip:
                continue
            try:
                t = p.cpu_times()
            except self.psutil.Error:
                continue
            out[p.pid] = t.user + t.system
        return out

    def between(self, before: dict[int, float], after: dict[int, float]) -> float:
        if self.psutil is None:
            return float("nan")
        return sum(t - before.get(pid, 0.0) for pid, t in after.items())


def in_process(task, episodes: int, dataset: Path | None) -> Sample:
    from robocfg.engine import RunOptions, run

    target = _target(dataset, task)
    sink = target.sink(task, target.root) if target is not None else None
    t0, c0 = time.perf_counter(), time.process_time()
    report = run(task, RunOptions(seed=0, episodes=episodes, sink=sink)).report
    if sink is not None:
        sink.close()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return Sample("in-process", 1, 0, episodes, 0.0, wall, report.summary.successes, worker_cpu=cpu, others_cpu=0.0)


def distributed(task, kind: str, workers: int, episodes: int, rnd: int, dataset: Path | None, tree: TreeCpu) -> Sample:
    from robocfg.datasets.shards import MergedShards
    from robocfg.engine import RunOptions
    from robocfg.executors.pool import ProcessPool
    from robocfg.executors.ray_pool import RayPool
    from robocfg.executors.recipe import EngineRecipe
    from robocfg.executors.session import plan_batches

    target = _target(dataset, task)
    recipe = EngineRecipe.of(task, RunOptions(seed=0, episodes=episodes, time_physics=True), target)  # physics timed
    pool = RayPool(workers, keep=kind == "ray-kept") if kind in RAY_KINDS else ProcessPool(workers, setup_of(kind))
    asked = time.time()
    t0 = time.perf_counter()
    pool.start(recipe)
    t1 = time.perf_counter()
    pids = {s.pid for s in pool.starts}
    before = tree.snapshot(pids)
    machine = CpuTimes.now()
    called = time.time()
    out = pool.run(recipe, plan_batches(episodes, workers, target is not None))
    returned = time.time()
    steal, busy = CpuTimes.now().since(machine)
    if target is not None:
        MergedShards(out.shards, target.root, target.fmt, target.extra_info).close()
    t2 = time.perf_counter()
    after = tree.snapshot(pids)
    assert not out.lost, out.lost
    first: dict[int, float] = {}
    last: dict[int, float] = {}
    for b in out.done:
        first[b.pid] = min(first.get(b.pid, math.inf), b.cpu[0])
        last[b.pid] = max(last.get(b.pid, -math.inf), b.cpu[1])
    runs = out.runs
    firsts, first_threads = {}, {}
    for b in sorted(out.done, key=lambda b: b.cpu[0]):
        if b.runs:
            firsts.setdefault(b.pid, b.runs[0].cpu)
            first_threads.setdefault(b.pid, b.runs[0].thread_cpu)
    return Sample(kind, workers, rnd, episodes, t1 - t0, t2 - t1, out.report.summary.successes,
                  statistics.median(s.opening - asked for s in pool.starts),
                  statistics.median(s.created - asked for s in pool.starts),
                  statistics.median(s.ready - s.opening for s in pool.starts),
                  [r.cpu for r in runs], [r.thread_cpu for r in runs],
                  sum(last[p] - first[p] for p in first), tree.between(before, after),
                  statistics.median(firsts.values()), [s.niceness for s in pool.starts],
                  TimeLine.of(out.done, called, returned, len(pool.starts))
                  if all(hasattr(b, "wall") for b in out.done) else None,  # older robocfg: no stamps
                  first_thread_cpu=statistics.median(first_threads.values()),
                  usage=[getattr(r, "usage", None) for r in runs],
                  threads=[getattr(s, "threads", 0) for s in pool.starts],
                  math_threads=[getattr(s, "math_threads", 0) for s in pool.starts], steal_pct=steal, busy_pct=busy,
                  episode_wall=[r.wall for r in runs], episode_physics=[r.physics for r in runs])


def _settle(tree: TreeCpu, limit: float = 30.0) -> float:
    """Wait until this process and those under it (a local Ray's prestarted workers booting, the
    last run's workers leaving) use under half a core over 0.5 s, at most ``limit`` s; return how
    long it took."""
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < limit:
        before = tree.snapshot(set())
        time.sleep(0.5)
        used = tree.between(before, tree.snapshot(set()))
        if math.isnan(used) or used < 0.25:  # NaN without psutil
            break
    return time.perf_counter() - t0


def _spin(n: int) -> float:
    """CPU time (s) of ``n`` iterations of a fixed pure-Python loop in this process."""
    t, x = time.process_time(), 0
    for i in range(n):
        x += i * i
    return time.process_time() - t


def _stream(n: int) -> float:
    """CPU time (s) of ``n`` sums over a 32 MiB array in this process (memory-bound: the data comes
    from memory, not from a core's caches, on every pass)."""
    import numpy as np

    a = np.ones(4 << 20)
    a.sum()
    t = time.process_time()
    for _ in range(n):
        a.sum()
    return time.process_time() - t


_WORLD: list = []  # the physics kernel's world, built once per process


def _physics(task_path: str, n: int) -> float:
    """CPU time (s) of ``n`` bare ``World.step()`` calls on the task's world (robot at home, the
    object on the table), built on this process's first call: the physics engine alone."""
    if not _WORLD:
        from robocfg.checks import load_task
        from robocfg.sim.world import World

        task = load_task(task_path)
        world = World(task)
        world.add_body(task.config.pick_place.object)
        _WORLD.append(world)
    t = time.process_time()
    _WORLD[0].step(n)
    return time.process_time() - t


def core_speed(counts: list[int], n: int = 3_000_000, kernel=_spin) -> dict[int, float]:
    """For each worker count w: the CPU time of a fixed kernel alone ÷ its median CPU time with w
    copies running at once in w processes (1.0: a core is as fast with w busy; < 1: cores slow
    down when many are busy — turbo limits, shared caches, hyper-threads, memory bandwidth — which
    no executor changes). ``kernel``: a pure-Python loop (:func:`_spin`, ``n`` iterations: the
    core itself), sums over a large array (:func:`_stream`, ``n`` passes: memory bandwidth) or
    bare physics steps (:func:`_physics`: the engine with no robocfg code around it).
    Processes from the same fork server the pool uses."""
    import multiprocessing as mp

    ctx = mp.get_context("forkserver")
    out = {}
    alone = None
    for w in sorted(set(counts)):
        with ctx.Pool(w) as p:
            p.map(kernel, [max(1, n // 20)] * w)  # all started and warm
            # the least disturbed of three tries (another tenant's burst makes a try slower)
            cpu = min(statistics.median(p.map(kernel, [n] * w, chunksize=1)) for _ in range(3))
        alone = cpu if alone is None else alone
        out[w] = alone / cpu
    return out


def start_costs(task) -> tuple[float, float, float]:
    """(fresh process, first pool worker, next pool worker) start times (s): a new interpreter that
    imports robocfg and opens a pick-place session (world, model, controllers); a process pool's
    worker doing the same from a fork server that has imported robocfg (the first call includes
    starting that server); each timed until the worker has opened its session and gone."""
    import subprocess
    import sys

    from robocfg.engine import RunOptions
    from robocfg.executors.pool import ProcessPool
    from robocfg.executors.recipe import EngineRecipe
    from robocfg.executors.session import Batch

    code = ("import time; t = time.perf_counter()\n"
            "from robocfg.sim.quiet import quiet_import; quiet_import()\n"
            "from robocfg.checks import load_task; from robocfg.engine import RunOptions, open_session\n"
            f"s = open_session(load_task({str(task.path)!r}), RunOptions(seed=0)); s.close()\n"
            "print(time.perf_counter() - t)")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    fresh = time.perf_counter() - t0
    recipe = EngineRecipe.of(task, RunOptions(seed=0, episodes=1))
    times = []
    for _ in range(2):
        t0 = time.perf_counter()
        ProcessPool(1).run(recipe, [Batch(0, ())])
        times.append(time.perf_counter() - t0)
    return fresh, times[0], times[1]


def _cpu_model() -> str:
    """The CPU's model name and its physical cores (Linux ``/proc/cpuinfo``; psutil)."""
    model = "?"
    try:
        with open("/proc/cpuinfo") as f:
            model = next((ln.split(":", 1)[1].strip() for ln in f if ln.startswith("model name")), "?")
    except OSError:
        pass
    try:
        import psutil

        physical = psutil.cpu_count(logical=False)
    except ImportError:
        physical = None
    return f"{model}, {physical} physical cores, {os.cpu_count()} logical"


def _spread(values: list[float], fmt: str = ".3f") -> str:
    """``median [min–max]`` of ``values``."""
    v = [x for x in values if x == x]
    if not v:
        return "-"
    med = statistics.median(v)
    return f"{med:{fmt}}" if len(v) == 1 else f"{med:{fmt}} [{min(v):{fmt}}–{max(v):{fmt}}]"


def _med(values: list[float]) -> float:
    v = [x for x in values if x == x]
    return statistics.median(v) if v else float("nan")


def _pct(values: list[float]) -> str:
    """Half the spread (max − min) of ``values`` in % of their median ("" for one value)."""
    v = [x for x in values if x == x]
    return f"{50 * (max(v) - min(v)) / statistics.median(v):.0f}" if len(v) > 1 else ""


def _break_even(samples: list[Sample], ray_kind: str = "ray") -> int | None:
    """Episodes per worker from which Ray's throughput with its start is ≥ 0.9 × the pool's (median
    starts S and steady seconds per episode per worker τ: n ≥ (0.9 S_ray − S_pool) / (τ_pool − 0.9 τ_ray));
    None without both executors, or when Ray's steady rate alone is below 0.9 × the pool's."""
    pool = [s for s in samples if s.executor == "pool"]
    ray = [s for s in samples if s.executor == ray_kind]
    if not pool or not ray:
        return None
    s_p, s_r = _med([s.start_s for s in pool]), _med([s.start_s for s in ray])
    t_p, t_r = _med([s.run_s * s.workers / s.episodes for s in pool]), _med([s.run_s * s.workers / s.episodes for s in ray])
    if t_p - 0.9 * t_r <= 0:
        return None
    return max(0, math.ceil((0.9 * s_r - s_p) / (t_p - 0.9 * t_r)))


def rounds_needed(ratios: list[float], half_width: float = 0.05) -> int | None:
    """Rounds that bound the median of ``ratios`` to about ±``half_width`` at 95 %: (2 s / h)², with
    s the standard deviation of their logarithm (None with fewer than 2 ratios)."""
    if len(ratios) < 2:
        return None
    s = statistics.stdev(math.log(r) for r in ratios)
    return max(1, math.ceil((2 * s / half_width) ** 2))


def summarise(samples: list[Sample], counts: list[int], rounds: int) -> dict:
    """Print the tables; return them as JSON-ready data."""
    by = {(s.executor, s.workers, s.round): s for s in samples}
    kinds = [k for k in ("in-process", *POOL_KINDS, *RAY_KINDS) if any(s.executor == k for s in samples)]
    ray_kinds = [k for k in RAY_KINDS if k in kinds] or ["ray"]
    print(f"\n{'executor':<13}{'w':>3}{'eps':>5}{'steady ep/s':>12}{'±%':>5}{'ep/s+start':>11}{'start s':>8}"
          f"{'spawn s':>8}{'boot s':>7}{'build s':>8}{'episode ms':>11}{'±%':>5}{'1st ms':>7}{'worker ms/ep':>13}{'driver+ ms/ep':>14}"
          f"{'cpu ms/ep':>10}{'ok':>9}")
    table = []
    for kind in kinds:
        for w in ([1] if kind == "in-process" else counts):
            rows = [s for s in samples if s.executor == kind and s.workers == w]
            if not rows:
                continue
            ep_cpu = [c for s in rows for c in s.episode_cpu]
            worker = [s.worker_cpu / s.episodes for s in rows]
            others = [s.others_cpu / s.episodes for s in rows]
            cpu = [s.cpu_per_episode for s in rows]
            ok = f"{sum(s.successes for s in rows)}/{sum(s.episodes for s in rows)}"
            ep_med = [statistics.median(s.episode_cpu) for s in rows if s.episode_cpu]
            print(f"{kind:<13}{w:>3}{rows[0].episodes:>5}{_med([s.eps for s in rows]):>12.3f}"
                  f"{_pct([s.eps for s in rows]):>5}{_med([s.eps_with_start for s in rows]):>11.3f}"
                  f"{_med([s.start_s for s in rows]):>8.2f}{_med([s.spawn_s for s in rows]):>8.2f}"
                  f"{_med([s.boot_s for s in rows]):>7.2f}"
                  f"{_med([s.build_s for s in rows]):>8.2f}{1e3 * _med(ep_cpu):>11.0f}{_pct(ep_med):>5}"
                  f"{1e3 * _med([s.first_cpu for s in rows]):>7.0f}"
                  f"{1e3 * _med(worker):>13.0f}{1e3 * _med(others):>14.0f}{1e3 * _med(cpu):>10.0f}{ok:>9}")
            table.append({"executor": kind, "workers": w, "episodes": rows[0].episodes,
                          "eps": [s.eps for s in rows], "eps_with_start": [s.eps_with_start for s in rows],
                          "start_s": [s.start_s for s in rows], "spawn_s": [s.spawn_s for s in rows],
                          "boot_s": [s.boot_s for s in rows],
                          "build_s": [s.build_s for s in rows],
                          "episode_cpu_ms_median": 1e3 * statistics.median(ep_cpu) if ep_cpu else None,
                          "episode_thread_cpu_ms_median": 1e3 * statistics.median(
                              [c for s in rows for c in s.episode_thread_cpu]) if ep_cpu else None,
                          "first_episode_cpu_ms": [1e3 * s.first_cpu for s in rows],
                          "worker_cpu_ms_per_ep": [1e3 * c for c in worker],
                          "others_cpu_ms_per_ep": [1e3 * c for c in others],
                          "successes": sum(s.successes for s in rows)})
    print("(medians over the rounds; ±%: half the spread, max − min, in % of the median, of the runs' steady ep/s"
          " and of their median episode CPU)")
    print(f"\n{'ray as':<9}{'workers':>7}  {'pool efficiency':<24}{'ray/pool steady':<24}{'ray/pool +start':<24}"
          f"{'ray/pool episode cpu':<24}{'ray/pool cpu/ep':<24}{'rounds ±5 % (wall, cpu)':<25}{'n for +start ≥ 0.9':<18}")
    paired = []
    for ray_kind, w in itertools.product(ray_kinds, counts):
        eff, vs, vs_start, vs_ep, vs_cpu = [], [], [], [], []
        for r in range(rounds):
            p, p1, y = by.get(("pool", w, r)), by.get(("pool", 1, r)), by.get((ray_kind, w, r))
            if p is not None and p1 is not None:
                eff.append(p.eps / (w * p1.eps))
            if p is not None and y is not None:
                vs.append(y.eps / p.eps)
                vs_start.append(y.eps_with_start / p.eps_with_start)
                vs_ep.append(statistics.median(y.episode_cpu) / statistics.median(p.episode_cpu))
                if y.cpu_per_episode == y.cpu_per_episode:
                    vs_cpu.append(p.cpu_per_episode / y.cpu_per_episode)  # > 1: Ray cheaper
        need, need_cpu = rounds_needed(vs), rounds_needed(vs_ep)
        n_even = _break_even([s for s in samples if s.workers == w], ray_kind)
        print(f"{ray_kind:<9}{w:>7}  {_spread(eff, '.2f'):<24}{_spread(vs, '.2f'):<24}{_spread(vs_start, '.2f'):<24}"
              f"{_spread(vs_ep, '.3f'):<24}{_spread(vs_cpu, '.3f'):<24}{f'{need}, {need_cpu}':<25}"
              f"{'-' if n_even is None else n_even}")
        paired.append({"ray": ray_kind, "workers": w, "pool_efficiency": eff, "ray_over_pool": vs, "ray_over_pool_with_start": vs_start,
                       "ray_over_pool_episode_cpu": vs_ep, "pool_cpu_over_ray_cpu_per_episode": vs_cpu,
                       "rounds_for_5pct": need, "rounds_for_5pct_episode_cpu": need_cpu,
                       "episodes_per_worker_for_ray_with_start_0_9": n_even})
    if any(p["ray_over_pool"] for p in paired):
        print("(ray/pool episode cpu: Ray's median CPU per episode ÷ the pool's, > 1 = Ray's episodes cost more;"
              " ray/pool cpu/ep: the pool's machine CPU per episode ÷ Ray's, < 1 = Ray costs more in all)")
    where = where_time_goes(samples, counts, rounds)
    executors = [k for k in kinds if k != "in-process"]
    return {"rows": table, "paired": paired, **where, "usage": usage_table(samples, executors, counts),
            "variants": variant_table(samples, executors, counts, rounds)}


def _factors(a: Sample, b: Sample) -> tuple[float, float, float] | None:
    """Throughput per worker of ``a`` ÷ that of ``b`` as the product of three factors: episode CPU
    (``b``'s CPU per episode ÷ ``a``'s: > 1 = ``a``'s episodes cost less CPU), core share
    (``a``'s episode CPU ÷ episode wall over ``b``'s: < 1 = ``a``'s workers waited longer for a
    core mid-episode) and busy share (``a``'s episode wall ÷ its worker-seconds over ``b``'s: < 1 =
    ``a``'s workers sat longer outside episodes: lead, gaps, tail, end). Their product is
    (``a``.eps / ``a``.workers) ÷ (``b``.eps / ``b``.workers) exactly."""
    ta, tb = a.time_line, b.time_line
    if ta is None or tb is None or min(ta.episode_cpu, tb.episode_cpu, ta.total, tb.total) <= 0:
        return None
    cpu = (tb.episode_cpu / b.episodes) / (ta.episode_cpu / a.episodes)
    core = (ta.episode_cpu / ta.episodes) / (tb.episode_cpu / tb.episodes)
    busy = (ta.episodes / ta.total) / (tb.episodes / tb.total)
    return cpu, core, busy


def where_time_goes(samples: list[Sample], counts: list[int], rounds: int) -> dict:
    """Print where each run's worker-seconds went (:class:`TimeLine`) and the efficiency and Ray ÷
    pool split into factors (:func:`_factors`); return both as JSON-ready data."""
    print("\nWhere the workers' time went (% of workers × run s; medians over the rounds):")
    print(f"{'executor':<13}{'w':>3}{'run s':>7}{'episodes':>9}{'had core':>9}{'lead':>7}{'batch':>7}{'gaps':>7}"
          f"{'ms/gap':>7}{'imbal.':>7}{'end':>7}{'end ms':>7}")
    rows = []
    for kind in (*POOL_KINDS, *RAY_KINDS):
        for w in counts:
            runs = [s for s in samples if s.executor == kind and s.workers == w and s.time_line is not None]
            if not runs:
                continue
            tl = [s.time_line for s in runs]
            share = {k: [100 * getattr(t, k) / t.total for t in tl if t is not None]
                     for k in ("episodes", "lead", "batch", "gaps", "imbalance", "end")}
            had_core = [100 * t.episode_cpu / t.episodes for t in tl if t is not None]
            ms_gap = [1e3 * t.gaps / t.n_gaps for t in tl if t is not None and t.n_gaps]
            end_ms = [1e3 * t.end / w for t in tl if t is not None]
            print(f"{kind:<13}{w:>3}{_med([s.run_s for s in runs]):>7.2f}{_med(share['episodes']):>9.1f}"
                  f"{_med(had_core):>9.1f}{_med(share['lead']):>7.1f}{_med(share['batch']):>7.1f}{_med(share['gaps']):>7.1f}"
                  f"{_med(ms_gap):>7.2f}{_med(share['imbalance']):>7.1f}{_med(share['end']):>7.1f}{_med(end_ms):>7.0f}")
            rows.append({"executor": kind, "workers": w, "percent": share, "had_core_percent": had_core,
                         "ms_per_gap": ms_gap, "end_ms": end_ms})
    print("(episodes: inside episodes; had core: episode CPU ÷ episode wall; lead: run() called → first batch;"
          " batch: in batches outside episodes; gaps: between batches (ms/gap: per gap, ≈ per episode without a"
          " dataset); imbal.: idle after its last batch while others finish; end: the last batch → run() returned"
          " (report, stopping workers), end ms: its length)")
    by = {(s.executor, s.workers, s.round): s for s in samples}
    ray_kinds = [k for k in RAY_KINDS if any(s.executor == k for s in samples)]
    print(f"\n{'workers':>7}  {'pool efficiency = cpu × core × busy':<36}"
          + "".join(f"{k + '/pool steady = cpu × core × busy':<42}" for k in ray_kinds))
    factors = []
    for w in counts:
        eff: list[tuple[float, float, float]] = []
        vs: dict[str, list[tuple[float, float, float]]] = {k: [] for k in ray_kinds}
        for r in range(rounds):
            p, p1 = by.get(("pool", w, r)), by.get(("pool", 1, r))
            if p is not None and p1 is not None and (f := _factors(p, p1)) is not None:
                eff.append(f)
            for k in ray_kinds:
                y = by.get((k, w, r))
                if p is not None and y is not None and (f := _factors(y, p)) is not None:
                    vs[k].append(f)

        def cols(fs: list[tuple[float, float, float]]) -> str:
            if not fs:
                return "-"
            return (f"{_med([a * b * c for a, b, c in fs]):.2f} = {_med([f[0] for f in fs]):.2f} × "
                    f"{_med([f[1] for f in fs]):.2f} × {_med([f[2] for f in fs]):.2f}")

        print(f"{w:>7}  {cols(eff):<36}" + "".join(f"{cols(vs[k]):<42}" for k in ray_kinds))
        factors.append({"workers": w, "pool_efficiency_factors": eff, "ray_over_pool_factors": vs})
    print("(medians over the rounds of each factor; cpu: episode CPU of the reference ÷ this one's (< 1: episodes"
          " cost more CPU — slower cores when all are busy, shared caches); core: share of episode wall with a core,"
          " relative; busy: share of worker-seconds inside episodes, relative (< 1: more idle — lead, gaps, tail, end))")
    return {"time_line": rows, "factors": factors}


def main() -> None:
    from robocfg.executors.session import DatasetTarget  # noqa: F401  (fail early without robocfg)

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    cores = len(os.sched_getaffinity(0))
    ap.add_argument("--workers", default=",".join(str(w) for w in (1, 2, 4, 8, 16) if w <= cores) or "1")
    ap.add_argument("--per-worker", type=int, default=16, help="episodes per worker in each run")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds (pool and Ray alternate first)")
    ap.add_argument("--ray", action="store_true", help="also run each worker count on Ray actors")
    ap.add_argument("--ray-kept", action="store_true",
                    help="also run each worker count on kept Ray actors (RayPool(keep=True): processes reused across runs)")
    ap.add_argument("--ray-worker-niceness", type=int, default=None,
                    help="niceness of the local Ray's workers (default: robocfg's, 0; Ray's own default is 15)")
    ap.add_argument("--pool-variants", default="single",
                    help="pool worker set-ups run side by side: single (what --workers does), default (math "
                         "libraries' own thread count: the old pool), pin (workers bound to cores), malloc "
                         "(glibc mmap/trim thresholds raised); e.g. single,default,pin")
    ap.add_argument("--dataset", action="store_true", help="record a state-only LeRobot dataset (shards merged)")
    ap.add_argument("--no-in-process", action="store_true", help="skip the in-process reference row")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    counts = [int(w) for w in args.workers.split(",")]
    if 1 not in counts:
        counts = [1, *counts]  # the efficiency's reference

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task

    tmp = Path(tempfile.mkdtemp(prefix="bench_scaling_"))
    task = load_task(_task_without_cameras(tmp))
    n_ds = [0]

    def ds() -> Path | None:
        n_ds[0] += 1
        return tmp / f"ds{n_ds[0]}" if args.dataset else None

    load0 = os.getloadavg()[0]
    print(f"cores: {cores} ({_cpu_model()})   load average: {load0:.2f}   episodes per worker: {args.per_worker}"
          f"   rounds: {args.rounds}   dataset: {'state-only LeRobot' if args.dataset else 'none'}   python {sys.version.split()[0]}")
    fresh, first, warm = start_costs(task)
    print(f"start to an open session: fresh process {fresh:.2f} s, pool worker {warm:.2f} s "
          f"(first pool of this process, fork server start included: {first:.2f} s)")
    speed = core_speed(counts)
    memory = core_speed(counts, 40, _stream)
    physics = core_speed(counts, 1000, functools.partial(_physics, str(task.path)))
    print("core speed with w processes busy (a fixed pure-Python loop's CPU time alone ÷ with w at once): "
          + ", ".join(f"w={w} {f:.2f}" for w, f in speed.items()))
    print("memory speed with w processes busy (sums over a 32 MiB array, CPU time alone ÷ with w at once): "
          + ", ".join(f"w={w} {f:.2f}" for w, f in memory.items()))
    print("physics speed with w processes busy (1000 bare steps of the task's world at rest, CPU time alone ÷ with w at once): "
          + ", ".join(f"w={w} {f:.2f}" for w, f in physics.items()))
    tree = TreeCpu()
    samples = [] if args.no_in_process else [in_process(task, args.per_worker, ds())]
    kinds = [*pool_kinds(args.pool_variants), *(["ray"] if args.ray else []), *(["ray-kept"] if args.ray_kept else [])]
    if any(k in RAY_KINDS for k in kinds):
        import ray

        from robocfg.executors import ray_pool

        if args.ray_worker_niceness is not None:
            ray_pool.WORKER_NICENESS = args.ray_worker_niceness
        # Ray CPUs are counted, not bound: kept actors hold theirs while idle, so fresh actors beside
        # them need as many again
        ray_cpus = max(counts) * sum(k in RAY_KINDS for k in kinds)
        ray_pool.init_ray(ray, num_cpus=ray_cpus)
        waited = _settle(TreeCpu())
        print(f"local Ray {ray.__version__} started with num_cpus={ray_cpus} before any timing"
              f" (then {waited:.1f} s until its prestarted workers were idle)")
    for rnd in range(args.rounds):
        for w in counts:
            order = kinds[rnd % len(kinds):] + kinds[:rnd % len(kinds)]  # who goes first rotates
            for kind in order:
                settled = _settle(tree, 10.0)  # the last run's exits, Ray refilling its idle workers
                s = distributed(task, kind, w, w * args.per_worker, rnd, ds(), tree)
                samples.append(s)
                if rnd == 0 and w == counts[0]:
                    print(f"  {kind} workers' niceness: {sorted(set(s.niceness))} (driver: {os.nice(0)})")
                print(f"  round {rnd} {kind:<12} w={w:<2} start {s.start_s:5.2f} s  run {s.run_s:6.2f} s  "
                      f"{s.eps:6.3f} ep/s  episode cpu {1e3 * statistics.median(s.episode_cpu):4.0f} ms  "
                      f"load {os.getloadavg()[0]:.2f}  (waited {settled:.1f} s for quiet before it)", flush=True)
    if any(k in RAY_KINDS for k in kinds):
        import ray

        from robocfg.executors.ray_pool import release_kept

        release_kept(ray)
        ray.shutdown()
    out = summarise(samples, counts, args.rounds)
    print(f"load average: {load0:.2f} before, {os.getloadavg()[0]:.2f} after")
    if args.json:
        Path(args.json).write_text(json.dumps({"cores": cores, "per_worker": args.per_worker, "rounds": args.rounds,
                                               "dataset": args.dataset, "core_speed": speed,
                                               "memory_speed": memory, "physics_speed": physics, **out}, indent=2) + "\n")


if __name__ == "__main__":
    main()
