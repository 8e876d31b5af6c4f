"""Where a pick-place episode's CPU goes: PyBullet's ``stepSimulation`` vs robocfg's own work, by
bucket, and the cost of a state-only dataset, in CPU time (``time.process_time``: on a shared,
loaded machine wall time mostly measures the other jobs).

    python benchmarks/bench_control_cost.py --episodes 16 [--task pick_place] [--formats lerobot,hdf5] [--json out.json]

One process, one session per row of the same task (seed 0): episode k runs without a dataset and
then with a state-only dataset of each of ``--formats`` (default: lerobot), in turn, so machine
load falls on all alike; figures are medians over episodes 1..N (episode 0 warms up, and with it
the writer's first use: its imports and the file it opens). The cost of a format is the median of
per-episode CPU ratios (dataset / none); what a run pays once per format — the writer module's
first import (h5py for hdf5), opening the writer and its ``close()`` — is measured apart (CPU ms, ``fixed_ms``). The buckets wrap the named functions with
``process_time`` (a wrapper costs ≈ 1–2 µs a call, included in its bucket; nested calls count
once, in the outer bucket); "other" is the rest of the episode (world restore, spawning the
object, the state machine's own checks, the step loop).
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import shutil
import statistics as st
import tempfile
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

BUCKETS = (  # (module, class, function, label)
    ("robocfg.sim.robot", "ArmHandle", "command", "motor commands (arm)"),
    ("robocfg.sim.world", "World", "_check", "divergence checks"),
    ("robocfg.kinematics.model", "KinematicModel", "ik", "IK"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "_choose_grasp", "grasp choice"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "__init__", "min-jerk timing"),
    ("robocfg.motion.trajectory", "Trajectory", "evaluate", "trajectory sampling"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "update", "gripper update"),
)


class Meter:
    """CPU seconds per label; ``stepSimulation`` and the bucket functions wrapped."""

    def __init__(self) -> None:
        self.acc: dict[str, float] = defaultdict(float)
        self._depth = 0

    def wrap(self, holder: Any, name: str, label: str) -> None:
        f = getattr(holder, name)

        def timed(*a: Any, **k: Any) -> Any:
            if self._depth:
                return f(*a, **k)
            self._depth += 1
            c0 = time.process_time()
            try:
                return f(*a, **k)
            finally:
                self.acc[label] += time.process_time() - c0
                self._depth -= 1

        setattr(holder, name, timed)

    def install(self) -> None:
        import robocfg.sim.world as world_module

        self.wrap(world_module.p, "stepSimulation", "stepSimulation")
        for mod, cls, fn, label in BUCKETS:
            self.wrap(getattr(importlib.import_module(mod), cls), fn, label)

    def snapshot(self) -> dict[str, float]:
        return dict(self.acc)


def _task(name: str):
    from robocfg.checks import load_task
    from robocfg.config import catalog

    t = load_task(catalog.find("tasks", name))
    return dataclasses.replace(t, config=t.config.model_copy(update={"cameras": []}))


def _episode(session: Any, k: int, meter: Meter) -> tuple[float, dict[str, float]]:
    before, c0 = meter.snapshot(), time.process_time()
    session.run(k)
    cpu = time.process_time() - c0
    after = meter.snapshot()
    return cpu, {key: after.get(key, 0.0) - before.get(key, 0.0) for key in after}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=16)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--formats", default="lerobot", help="comma-separated: lerobot, hdf5")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    formats = [f for f in args.formats.split(",") if f]

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import robocfg.datasets.sink as sink_module
    from robocfg.datasets.sink import DatasetSink
    from robocfg.engine import RunOptions, open_session

    meter = Meter()
    meter.install()
    task = _task(args.task)
    tmp = Path(tempfile.mkdtemp(prefix="bench_control_"))
    info = {"task_path": str(task.path), "seed": 0, "arm": None, "robot_override": None}
    sinks = {f: DatasetSink(tmp / f, f, task, extra_info=info) for f in formats}  # type: ignore[arg-type]
    sessions = {"none": open_session(task, RunOptions(seed=0))}
    sessions |= {f: open_session(task, RunOptions(seed=0, sink=sinks[f])) for f in formats}
    runs: dict[str, list[tuple[float, dict[str, float]]]] = {k: [] for k in sessions}
    fixed: dict[str, float] = defaultdict(float)
    make_writer = sink_module.make_writer

    def timed_make_writer(fmt: Any, *a: Any) -> Any:  # the writer's first use: imports, file opened
        c0 = time.process_time()
        try:
            return make_writer(fmt, *a)
        finally:
            fixed[fmt] += time.process_time() - c0

    sink_module.make_writer = timed_make_writer
    try:
        for session in sessions.values():
            session.run(0)
        for k in range(1, args.episodes + 1):
            for key, session in sessions.items():
                runs[key].append(_episode(session, k, meter))
        for f in formats:
            c0 = time.process_time()
            sinks[f].close()
            fixed[f] += time.process_time() - c0
    finally:
        for session in sessions.values():
            session.close()
        shutil.rmtree(tmp, ignore_errors=True)

    def med(values: list[float]) -> float:
        return float(st.median(values))

    none = runs["none"]
    physics = med([b.get("stepSimulation", 0.0) for _, b in none])
    cpu = med([c for c, _ in none])
    own = med([(c - b.get("stepSimulation", 0.0)) / b.get("stepSimulation", 1.0) for c, b in none])
    buckets = {label: med([b.get(label, 0.0) for _, b in none]) for *_, label in BUCKETS}
    cost = {f: med([d[0] / n[0] for n, d in zip(none, runs[f], strict=True)]) for f in formats}
    res = {"task": args.task, "episodes": args.episodes, "cpu_per_episode_ms": round(cpu * 1e3, 2),
           "physics_per_episode_ms": round(physics * 1e3, 2), "own_share_of_physics": round(own, 3),
           "buckets_ms": {k: round(v * 1e3, 2) for k, v in buckets.items()},
           "other_ms": round((cpu - physics - sum(buckets.values())) * 1e3, 2),
           "state_only_dataset_cost": {f: round(c, 3) for f, c in cost.items()},
           "dataset_cpu_per_episode_ms": {f: round(med([c for c, _ in runs[f]]) * 1e3, 2) for f in formats},
           "fixed_ms": {f: round(v * 1e3, 1) for f, v in fixed.items()}}
    print(f"{args.task}: {cpu * 1e3:.1f} ms CPU per episode, {physics * 1e3:.1f} ms in stepSimulation; "
          f"robocfg's own work {own:.1%} of physics (median over {args.episodes} episodes)")
    for label, v in sorted(buckets.items(), key=lambda kv: -kv[1]):
        print(f"  {label:22s} {v * 1e3:7.2f} ms  {v / physics:6.1%} of physics")
    print(f"  {'other':22s} {res['other_ms']:7.2f} ms  {res['other_ms'] / 1e3 / physics:6.1%} of physics")
    for f in formats:
        print(f"state-only {f} dataset: {cost[f]:.3f}x the CPU of the same episode without (median of per-episode "
              f"ratios); once per run: {res['fixed_ms'][f]:.1f} ms (writer opened incl. first imports, and closed)")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
