"""Where a pick-place episode's CPU goes: PyBullet's ``stepSimulation`` vs robocfg's own work, by
bucket, and the cost of a state-only dataset, in CPU time (``time.process_time``: on a shared,
loaded machine wall time mostly measures the other jobs).

    python benchmarks/bench_control_cost.py --episodes 16 [--task pick_place] [--formats lerobot,hdf5] [--json out.json]

One process, one session per row of the same task (seed 0): episode k runs without a dataset and
then with a state-only dataset of each of ``--formats`` (default: lerobot; ``--formats ""``: none),
in turn, so machine load falls on all alike; figures are medians over episodes 1..N (episode 0
warms up, and with it the writer's first use: its imports and the file it opens). The cost of a
format is the median of per-episode CPU ratios (dataset / none); what a run pays once per format —
the writer module's first import (h5py for hdf5), opening the writer and its ``close()`` — is
measured apart (CPU ms, ``fixed_ms``).

The buckets wrap the named functions with ``process_time`` (nested calls count once, in the outer
bucket): the motor calls themselves (``setJointMotorControlArray``/``setJointMotorControl2``, arm
and gripper, wherever robocfg sends them), the divergence checks, IK, the grasp choice, min-jerk
timing, trajectory sampling, gripper updates; "other" is the rest of the episode (the step loop,
world restore, spawning the object, the state machine's own checks). The timers cost CPU
themselves (≈ 1–4 µs a call, ≈ 4 000 calls an episode, which would add ≈ 5–10 % to "own" on a
2-core laptop): the benchmark measures its wrapper on a no-op before the episodes and removes,
per call, the part that fell inside a timed interval from that interval and the rest from "own"
("timer_overhead_ms" says how much). robocfg's own work = (episode CPU − timer overhead −
``stepSimulation``) ÷ ``stepSimulation``, the issue's "own work ÷ physics time".
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

BUCKETS = (  # (module, class or None for a module function, function, label)
    ("pybullet", None, "setJointMotorControlArray", "motor calls"),
    ("pybullet", None, "setJointMotorControl2", "motor calls"),
    ("robocfg.sim.world", "World", "_check", "divergence checks"),
    ("robocfg.kinematics.model", "KinematicModel", "ik", "IK"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "_choose_grasp", "grasp choice"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "__init__", "min-jerk timing"),
    ("robocfg.motion.trajectory", "Trajectory", "evaluate", "trajectory sampling"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "update", "gripper update"),
)


class Meter:
    """CPU seconds per label; ``stepSimulation`` and the bucket functions wrapped. ``calls``
    counts the timed calls per label, ``passed`` the nested ones that only passed through."""

    def __init__(self) -> None:
        self.acc: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.passed = 0
        self._depth = 0
        self.cost_in = self.cost_out = self.cost_pass = 0.0  # s per call, from calibrate()

    def timed(self, f: Any, label: str) -> Any:
        def timed(*a: Any, **k: Any) -> Any:
            if self._depth:
                self.passed += 1
                return f(*a, **k)
            self._depth += 1
            c0 = time.process_time()
            try:
                return f(*a, **k)
            finally:
                self.acc[label] += time.process_time() - c0
                self.calls[label] += 1
                self._depth -= 1

        return timed

    def wrap(self, holder: Any, name: str, label: str) -> None:
        setattr(holder, name, self.timed(getattr(holder, name), label))

    def install(self) -> None:
        import pybullet

        self.wrap(pybullet, "stepSimulation", "stepSimulation")
        for mod, cls, fn, label in BUCKETS:
            m = importlib.import_module(mod)
            self.wrap(m if cls is None else getattr(m, cls), fn, label)

    def calibrate(self, n: int = 20000, repeats: int = 5) -> None:
        """The wrapper's own CPU per call on a no-op (medians of ``repeats``): inside the timed
        interval (``cost_in``), outside it (``cost_out``), and passing a nested call through."""
        noop = self.timed(abs, "_calibration")
        inside, outside, passing = [], [], []
        for _ in range(repeats):
            self.acc["_calibration"] = 0.0
            c0 = time.process_time()
            for _ in range(n):
                noop(1)
            total = time.process_time() - c0
            c0 = time.process_time()
            for _ in range(n):
                abs(1)
            bare = time.process_time() - c0
            inside.append(self.acc["_calibration"] / n)
            outside.append((total - bare) / n - inside[-1])
            self._depth = 1
            c0 = time.process_time()
            for _ in range(n):
                noop(1)
            passing.append((time.process_time() - c0 - bare) / n)
            self._depth = 0
        self.cost_in, self.cost_out, self.cost_pass = st.median(inside), st.median(outside), st.median(passing)
        for d in (self.acc, self.calls):
            d.pop("_calibration", None)
        self.passed = 0

    def snapshot(self) -> dict[str, float]:
        """CPU s per label with the timers' in-interval cost removed, and ``_timers``: the CPU s
        the timers cost outside their intervals (calls that were timed, and passed through)."""
        out = {k: v - self.calls[k] * self.cost_in for k, v in self.acc.items()}
        out["_timers"] = sum(self.calls.values()) * (self.cost_in + self.cost_out) + self.passed * self.cost_pass
        return out


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
    meter.calibrate()
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
    timers = med([b.get("_timers", 0.0) for _, b in none])
    cpu = med([c - b.get("_timers", 0.0) for c, b in none])  # the episode without the benchmark's timers
    own = med([(c - b.get("_timers", 0.0) - b.get("stepSimulation", 0.0)) / b.get("stepSimulation", 1.0)
               for c, b in none])
    labels = list(dict.fromkeys(label for *_, label in BUCKETS))
    buckets = {label: med([b.get(label, 0.0) for _, b in none]) for label in labels}
    def net(run: tuple[float, dict[str, float]]) -> float:  # an episode's CPU without the benchmark's timers
        return run[0] - run[1].get("_timers", 0.0)

    cost = {f: med([net(d) / net(n) for n, d in zip(none, runs[f], strict=True)]) for f in formats}
    res = {"task": args.task, "episodes": args.episodes, "cpu_per_episode_ms": round(cpu * 1e3, 2),
           "physics_per_episode_ms": round(physics * 1e3, 2), "own_share_of_physics": round(own, 3),
           "buckets_ms": {k: round(v * 1e3, 2) for k, v in buckets.items()},
           "other_ms": round((cpu - physics - sum(buckets.values())) * 1e3, 2),
           "timer_overhead_ms": round(timers * 1e3, 2),
           "timer_cost_us": {"inside": round(meter.cost_in * 1e6, 3), "outside": round(meter.cost_out * 1e6, 3),
                             "pass_through": round(meter.cost_pass * 1e6, 3)},
           "state_only_dataset_cost": {f: round(c, 3) for f, c in cost.items()},
           "dataset_cpu_per_episode_ms": {f: round(med([net(r) for r in runs[f]]) * 1e3, 2) for f in formats},
           "fixed_ms": {f: round(v * 1e3, 1) for f, v in fixed.items()}}
    print(f"{args.task}: {cpu * 1e3:.1f} ms CPU per episode, {physics * 1e3:.1f} ms in stepSimulation; "
          f"robocfg's own work {own:.1%} of physics (median over {args.episodes} episodes; the benchmark's "
          f"timers, {timers * 1e3:.1f} ms an episode at {meter.cost_in * 1e6:.2f} + {meter.cost_out * 1e6:.2f} µs a call, "
          f"removed)")
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
