"""Pick-place episodes/s on 1, 2, 4 ... N worker processes, and Ray actors next to them, in
interleaved rounds.

    python benchmarks/bench_scaling.py [--workers 1,2,4,8,16] [--per-worker 16] [--rounds 5] [--ray]
                                       [--dataset] [--no-in-process] [--json out.json]

Weak scaling: a run of worker count w runs ``per-worker × w`` episodes of the shipped pick-place task
without cameras (seed 0) through the executors the CLI uses (``--workers``: a process pool;
``--ray``: Ray actors on a local Ray started once, before any timing, as ``--executor ray`` starts
one — workers at the driver's niceness — with ``num_cpus`` = the largest worker count;
``--ray-worker-niceness 15`` gives Ray's own default). Each round runs, for every worker count, the pool and Ray one after the
other, pool first in even rounds and Ray first in odd ones (A B, B A, A B ...), so slow drifts of a
shared host's load fall on both alike; every figure is a median over the rounds, with its spread
(min–max), and Ray ÷ pool is taken within each round (paired) before its median.

What a run measures, each part apart:

* *start*: the pool's ``start()`` — workers started until every one has built its world — split
  into *boot* (asked → the worker begins opening the recipe: process creation, interpreter,
  imports, unpickling; a pool worker forks from a fork server that has imported robocfg, a Ray
  actor is a fresh interpreter) and *build* (world, kinematic model, controllers), medians over
  the workers;
* *steady*: the episodes on those workers, ``episodes / run s``;
* *CPU per episode*, robust to a host's load because waiting for a core costs no CPU time:
  ``episode ms`` — the worker process's CPU time over one episode (every thread), median over
  every episode of every round (``1st ms``: each worker's first episode, which pays what the
  worker imports or builds lazily); ``worker ms/ep`` — the workers' CPU from their first batch's start
  to their last batch's end ÷ episodes (adds what runs between episodes: receiving a batch,
  returning a result, an executor's own threads); ``driver+ ms/ep`` — the CPU of the driver and of
  every other process it started (fork server; Ray's raylet, GCS, agents and idle workers) during
  the run ÷ episodes (needs psutil). ``cpu ms/ep`` is their sum: the machine's CPU per episode.

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
import json
import math
import os
import statistics
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path


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

    @property
    def eps(self) -> float:
        return self.episodes / self.run_s

    @property
    def eps_with_start(self) -> float:
        return self.episodes / (self.run_s + self.start_s)

    @property
    def cpu_per_episode(self) -> float:
        return (self.worker_cpu + self.others_cpu) / self.episodes


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
    recipe = EngineRecipe.of(task, RunOptions(seed=0, episodes=episodes), target)
    pool = RayPool(workers) if kind == "ray" else ProcessPool(workers)
    asked = time.time()
    t0 = time.perf_counter()
    pool.start(recipe)
    t1 = time.perf_counter()
    pids = {s.pid for s in pool.starts}
    before = tree.snapshot(pids)
    out = pool.run(recipe, plan_batches(episodes, workers, target is not None))
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
    firsts = {}
    for b in sorted(out.done, key=lambda b: b.cpu[0]):
        if b.runs:
            firsts.setdefault(b.pid, b.runs[0].cpu)
    return Sample(kind, workers, rnd, episodes, t1 - t0, t2 - t1, out.report.summary.successes,
                  statistics.median(s.opening - asked for s in pool.starts),
                  statistics.median(s.created - asked for s in pool.starts),
                  statistics.median(s.ready - s.opening for s in pool.starts),
                  [r.cpu for r in runs], [r.thread_cpu for r in runs],
                  sum(last[p] - first[p] for p in first), tree.between(before, after),
                  statistics.median(firsts.values()), [s.niceness for s in pool.starts])


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


def _break_even(samples: list[Sample]) -> int | None:
    """Episodes per worker from which Ray's throughput with its start is ≥ 0.9 × the pool's (median
    starts S and steady seconds per episode per worker τ: n ≥ (0.9 S_ray − S_pool) / (τ_pool − 0.9 τ_ray));
    None without both executors, or when Ray's steady rate alone is below 0.9 × the pool's."""
    pool = [s for s in samples if s.executor == "pool"]
    ray = [s for s in samples if s.executor == "ray"]
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
    kinds = [k for k in ("in-process", "pool", "ray") if any(s.executor == k for s in samples)]
    print(f"\n{'executor':<11}{'w':>3}{'eps':>5}{'steady ep/s':>12}{'±%':>5}{'ep/s+start':>11}{'start s':>8}"
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
            print(f"{kind:<11}{w:>3}{rows[0].episodes:>5}{_med([s.eps for s in rows]):>12.3f}"
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
    print(f"\n{'workers':>7}  {'pool efficiency':<24}{'ray/pool steady':<24}{'ray/pool +start':<24}"
          f"{'ray/pool episode cpu':<24}{'ray/pool cpu/ep':<24}{'rounds ±5 % (wall, cpu)':<25}{'n for +start ≥ 0.9':<18}")
    paired = []
    for w in counts:
        eff, vs, vs_start, vs_ep, vs_cpu = [], [], [], [], []
        for r in range(rounds):
            p, p1, y = by.get(("pool", w, r)), by.get(("pool", 1, r)), by.get(("ray", w, r))
            if p is not None and p1 is not None:
                eff.append(p.eps / (w * p1.eps))
            if p is not None and y is not None:
                vs.append(y.eps / p.eps)
                vs_start.append(y.eps_with_start / p.eps_with_start)
                vs_ep.append(statistics.median(y.episode_cpu) / statistics.median(p.episode_cpu))
                if y.cpu_per_episode == y.cpu_per_episode:
                    vs_cpu.append(p.cpu_per_episode / y.cpu_per_episode)  # > 1: Ray cheaper
        need, need_cpu = rounds_needed(vs), rounds_needed(vs_ep)
        n_even = _break_even([s for s in samples if s.workers == w])
        print(f"{w:>7}  {_spread(eff, '.2f'):<24}{_spread(vs, '.2f'):<24}{_spread(vs_start, '.2f'):<24}"
              f"{_spread(vs_ep, '.3f'):<24}{_spread(vs_cpu, '.3f'):<24}{f'{need}, {need_cpu}':<25}"
              f"{'-' if n_even is None else n_even}")
        paired.append({"workers": w, "pool_efficiency": eff, "ray_over_pool": vs, "ray_over_pool_with_start": vs_start,
                       "ray_over_pool_episode_cpu": vs_ep, "pool_cpu_over_ray_cpu_per_episode": vs_cpu,
                       "rounds_for_5pct": need, "rounds_for_5pct_episode_cpu": need_cpu,
                       "episodes_per_worker_for_ray_with_start_0_9": n_even})
    if any(p["ray_over_pool"] for p in paired):
        print("(ray/pool episode cpu: Ray's median CPU per episode ÷ the pool's, > 1 = Ray's episodes cost more;"
              " ray/pool cpu/ep: the pool's machine CPU per episode ÷ Ray's, < 1 = Ray costs more in all)")
    return {"rows": table, "paired": paired}


def main() -> None:
    from robocfg.executors.session import DatasetTarget  # noqa: F401  (fail early without robocfg)

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    cores = len(os.sched_getaffinity(0))
    ap.add_argument("--workers", default=",".join(str(w) for w in (1, 2, 4, 8, 16) if w <= cores) or "1")
    ap.add_argument("--per-worker", type=int, default=16, help="episodes per worker in each run")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds (pool and Ray alternate first)")
    ap.add_argument("--ray", action="store_true", help="also run each worker count on Ray actors")
    ap.add_argument("--ray-worker-niceness", type=int, default=None,
                    help="niceness of the local Ray's workers (default: robocfg's, 0; Ray's own default is 15)")
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
    print(f"cores: {cores}   load average: {load0:.2f}   episodes per worker: {args.per_worker}   rounds: {args.rounds}"
          f"   dataset: {'state-only LeRobot' if args.dataset else 'none'}")
    fresh, first, warm = start_costs(task)
    print(f"start to an open session: fresh process {fresh:.2f} s, pool worker {warm:.2f} s "
          f"(first pool of this process, fork server start included: {first:.2f} s)")
    tree = TreeCpu()
    samples = [] if args.no_in_process else [in_process(task, args.per_worker, ds())]
    if args.ray:
        import ray

        from robocfg.executors import ray_pool

        if args.ray_worker_niceness is not None:
            ray_pool.WORKER_NICENESS = args.ray_worker_niceness
        ray_pool.init_ray(ray, num_cpus=max(counts))
    for rnd in range(args.rounds):
        for w in counts:
            kinds = ["pool", "ray"] if args.ray else ["pool"]
            for kind in kinds if rnd % 2 == 0 else kinds[::-1]:
                s = distributed(task, kind, w, w * args.per_worker, rnd, ds(), tree)
                samples.append(s)
                if rnd == 0 and w == counts[0]:
                    print(f"  {kind} workers' niceness: {sorted(set(s.niceness))} (driver: {os.nice(0)})")
                print(f"  round {rnd} {kind:<4} w={w:<2} start {s.start_s:5.2f} s  run {s.run_s:6.2f} s  "
                      f"{s.eps:6.3f} ep/s  episode cpu {1e3 * statistics.median(s.episode_cpu):4.0f} ms  "
                      f"load {os.getloadavg()[0]:.2f}", flush=True)
    if args.ray:
        import ray

        ray.shutdown()
    out = summarise(samples, counts, args.rounds)
    print(f"load average: {load0:.2f} before, {os.getloadavg()[0]:.2f} after")
    if args.json:
        Path(args.json).write_text(json.dumps({"cores": cores, "per_worker": args.per_worker, "rounds": args.rounds,
                                               "dataset": args.dataset, **out}, indent=2) + "\n")


if __name__ == "__main__":
    main()
