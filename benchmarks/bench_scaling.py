"""Pick-place episodes/s on 1, 2, 4 ... N worker processes, and Ray actors next to them.

    python benchmarks/bench_scaling.py [--workers 1,2,4,8,16] [--per-worker 8] [--ray] [--dataset] [--json out.json]

Weak scaling: each row runs ``per-worker × workers`` episodes of the shipped pick-place task
(seed 0) through the same executors the CLI uses (``--workers``: a process pool; ``--ray``: a
local Ray with one actor per worker; ``ray.init`` before the timing). Each row is timed in two
parts: *start* — the pool's ``start()``: its workers started (forked from the pool's fork server,
or a fresh interpreter per Ray actor) until every one has built its world, a fixed cost per run;
*run* — the episodes (and with ``--dataset``, state only, writing and merging the shards) on
those workers. ``ep/s`` is the steady throughput (episodes / run), ``ep/s+start`` counts the
start too (what a user waits for). Efficiency = steady throughput / (workers × the 1-worker
pool's); ``ray/pool`` compares Ray with the pool of the same worker count, steady and with the
start. The first row is the same episodes in the calling process (its world build included), the
reference a pool must beat.

The machine's load average is printed: on a shared machine the rows measure the contention too.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path


@dataclass
class Row:
    executor: str
    workers: int
    episodes: int
    wall_s: float  # the episodes on started workers (s)
    successes: int
    start_s: float = 0.0  # starting the workers until their worlds are built (s)

    @property
    def eps_per_s(self) -> float:
        return self.episodes / self.wall_s

    @property
    def eps_with_start(self) -> float:
        return self.episodes / (self.wall_s + self.start_s)


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


def in_process(task, episodes: int, dataset: Path | None) -> Row:
    from robocfg.engine import RunOptions, run

    target = _target(dataset, task)
    sink = target.sink(task, target.root) if target is not None else None
    t0 = time.perf_counter()
    report = run(task, RunOptions(seed=0, episodes=episodes, sink=sink)).report
    if sink is not None:
        sink.close()
    return Row("in-process", 1, episodes, time.perf_counter() - t0, report.summary.successes)


def distributed(task, kind: str, workers: int, episodes: int, dataset: Path | None) -> Row:
    from robocfg.datasets.shards import MergedShards
    from robocfg.engine import RunOptions
    from robocfg.executors.pool import ProcessPool
    from robocfg.executors.ray_pool import RayPool
    from robocfg.executors.recipe import EngineRecipe
    from robocfg.executors.session import plan_batches

    target = _target(dataset, task)
    recipe = EngineRecipe.of(task, RunOptions(seed=0, episodes=episodes), target)
    pool = RayPool(workers) if kind == "ray" else ProcessPool(workers)
    t0 = time.perf_counter()
    pool.start(recipe)
    t1 = time.perf_counter()
    out = pool.run(recipe, plan_batches(episodes, workers, target is not None))
    if target is not None:
        MergedShards(out.shards, target.root, target.fmt, target.extra_info).close()
    t2 = time.perf_counter()
    assert not out.lost, out.lost
    return Row(kind, workers, episodes, t2 - t1, out.report.summary.successes, t1 - t0)


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


def main() -> None:
    from robocfg.executors.session import DatasetTarget  # noqa: F401  (fail early without robocfg)

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    cores = len(os.sched_getaffinity(0))
    ap.add_argument("--workers", default=",".join(str(w) for w in (1, 2, 4, 8, 16) if w <= cores) or "1")
    ap.add_argument("--per-worker", type=int, default=8)
    ap.add_argument("--ray", action="store_true", help="also run each worker count on Ray actors")
    ap.add_argument("--dataset", action="store_true", help="record a state-only LeRobot dataset (shards merged)")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    counts = [int(w) for w in args.workers.split(",")]

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task

    tmp = Path(tempfile.mkdtemp(prefix="bench_scaling_"))
    task = load_task(_task_without_cameras(tmp))
    n_ds = [0]

    def ds() -> Path | None:
        n_ds[0] += 1
        return tmp / f"ds{n_ds[0]}" if args.dataset else None

    print(f"cores: {cores}   load average: {os.getloadavg()[0]:.2f}   episodes per worker: {args.per_worker}"
          f"   dataset: {'state-only LeRobot' if args.dataset else 'none'}")
    fresh, first, warm = start_costs(task)
    print(f"start to an open session: fresh process {fresh:.2f} s, pool worker {warm:.2f} s "
          f"(first pool of this process, fork server start included: {first:.2f} s)")
    rows = [in_process(task, args.per_worker, ds())]
    if args.ray:
        import logging

        import ray

        ray.init(num_cpus=max(counts), include_dashboard=False, logging_level=logging.ERROR, log_to_driver=False)
    for w in counts:
        rows.append(distributed(task, "pool", w, w * args.per_worker, ds()))
        if args.ray:
            rows.append(distributed(task, "ray", w, w * args.per_worker, ds()))
    base = next(r for r in rows if r.executor == "pool" and r.workers == 1).eps_per_s
    print(f"{'executor':<12}{'workers':>8}{'episodes':>9}{'start s':>9}{'run s':>8}{'ep/s':>8}{'ep/s+start':>11}"
          f"{'efficiency':>11}{'ray/pool':>9}{'+start':>8}{'ok':>5}")
    pool_at = {r.workers: r for r in rows if r.executor == "pool"}
    out = []
    for r in rows:
        eff = r.eps_per_s / (r.workers * base)
        p = pool_at[r.workers]
        vs, vs_start = ((r.eps_per_s / p.eps_per_s, r.eps_with_start / p.eps_with_start) if r.executor == "ray"
                        else (float("nan"), float("nan")))
        print(f"{r.executor:<12}{r.workers:>8}{r.episodes:>9}{r.start_s:>9.2f}{r.wall_s:>8.2f}{r.eps_per_s:>8.3f}"
              f"{r.eps_with_start:>11.3f}{eff:>11.2f}{'' if vs != vs else f'{vs:.2f}':>9}"
              f"{'' if vs_start != vs_start else f'{vs_start:.2f}':>8}{r.successes:>5}")
        out.append({**r.__dict__, "eps_per_s": r.eps_per_s, "eps_with_start": r.eps_with_start, "efficiency": eff,
                    "ray_over_pool": None if vs != vs else vs, "ray_over_pool_with_start": None if vs != vs else vs_start})
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    if args.ray:
        import ray

        ray.shutdown()
    if args.json:
        Path(args.json).write_text(json.dumps({"cores": cores, "per_worker": args.per_worker,
                                               "dataset": args.dataset, "rows": out}, indent=2) + "\n")


if __name__ == "__main__":
    main()
