"""Where a pick-place episode's CPU goes: PyBullet's ``stepSimulation`` vs robocfg's own work, by
bucket, and the cost of a state-only dataset, in CPU time (``time.process_time``: on a shared,
loaded machine wall time mostly measures the other jobs).

    python benchmarks/bench_control_cost.py --episodes 16 [--task pick_place] [--formats lerobot,hdf5] [--json out.json]

One process, one session per row of the same task (seed 0). Episode k (1..N; episode 0 warms up,
and with it the writer's first use: its imports and the file it opens) runs three ways, in an
order that rotates with k, so machine load falls on all alike:

* **untimed** — nothing wrapped: the episode's CPU;
* **physics** — ``stepSimulation`` alone wrapped (the fewest timers): the episode's physics CPU;
* **buckets** — every function of ``BUCKETS`` wrapped too, without a dataset and then with a
  state-only dataset of each of ``--formats`` (default: lerobot; ``--formats ""``: none).

The headline, robocfg's own work ÷ physics (the issue's "own work ÷ physics time"), is the median
over k of (CPU − timers − physics) ÷ physics in the physics-only run: one timer a physics step,
its cost calibrated on a no-op before the episodes and removed. A timer costs more in situ (after
a physics step, with cold caches) than in the calibration loop, so this reads a little high. Two
cross-checks without any benchmark timer in them: the untimed run split by the world's own wall
clock (``World.physics_seconds``, ``perf_counter`` around each step: preemption falls on both sides;
robocfg keeps that clock only where asked, ``RunOptions.time_physics``, so it runs in the untimed
run alone and its ≈ 0.2 µs a step count as own work there),
and the untimed run's CPU minus the physics-only run's physics (a difference of two runs: on a
loaded machine the same steps' CPU differs by 10–20 % between runs, so this one swings); the
bucketed run's own figure, higher still (its many timers' in-situ excess), is printed too.

The buckets are **exclusive**: a bucket's time excludes the wrapped calls inside it (IK inside the
grasp choice counts as IK), and what no bucket holds is "other". Besides the main costs (motor
calls, divergence checks, IK, grasp choice, min-jerk timing, trajectory sampling, gripper
updates) they name the rest of the episode: the step loop (playback and the world's step), the
straight lines' waypoints (IK aside), move set-up, convergence and gripper polls, support ray
casts, the world restore, the object spawn, the episode set-up, state reads, the episode record.
Bucket figures carry their timers' in-situ excess (≈ 1 µs or more per wrapped call beyond the
calibration), so buckets with many calls (the step loop holds each physics step's timer exit,
motor calls are ≈ one a step) read high; compare them with each other and across code versions,
and take the headline from the untimed run. The cost of a format is the median of per-episode CPU
ratios (dataset / none, both bucketed); what a run pays once per format — the writer module's
first import (h5py for hdf5), opening the writer and its ``close()`` — is measured apart (CPU
ms, ``fixed_ms``).
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

BUCKETS = (  # (module, class or None for a module function, function, label); exclusive (see Meter)
    ("pybullet", None, "setJointMotorControlArray", "motor calls"),
    ("pybullet", None, "setJointMotorControl2", "motor calls"),
    ("robocfg.sim.world", "World", "_check", "divergence checks"),
    ("robocfg.kinematics.model", "KinematicModel", "ik", "IK"),
    ("robocfg.runners.pick_place_grasp_choice", "GraspChoice", "_choose_grasp", "grasp choice"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "__init__", "min-jerk timing"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "positions_velocities", "trajectory sampling"),
    ("robocfg.motion.trajectory", "Trajectory", "evaluate", "trajectory sampling"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "positions", "trajectory sampling"),
    ("robocfg.motion.trajectory", "Trajectory", "positions", "trajectory sampling"),
    ("robocfg.motion.minjerk_path", "MinJerkPath", "step_targets", "trajectory sampling"),
    ("robocfg.motion.trajectory", "Trajectory", "step_targets", "trajectory sampling"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "update", "gripper update"),
    # the rest of the episode, by part ("other" is what none of these holds):
    ("robocfg.sim.playback", None, "_play_bare", "step loop"),
    ("robocfg.sim.playback", None, "_play_hooked", "step loop"),
    ("robocfg.sim.playback", None, "advance_idle", "step loop"),
    ("robocfg.sim.playback", None, "play_rows", "step loop"),
    ("robocfg.sim.world", "World", "step", "step loop"),
    ("robocfg.sim.world", "World", "periodic_check", "step loop"),
    ("robocfg.motion.moves", "ArmMover", "straight_path", "straight lines (IK aside)"),
    ("robocfg.motion.moves", "ArmMover", "straight_end", "straight lines (IK aside)"),
    ("robocfg.motion.moves", "ArmMover", "move", "move set-up"),
    ("robocfg.motion.moves", "ArmMover", "play", "move set-up"),
    ("robocfg.motion.moves", "ArmMover", "_stretch", "move set-up"),
    ("robocfg.motion.moves", "ArmMover", "converge", "convergence polls"),
    ("robocfg.motion.moves", "ArmMover", "close_until_held", "gripper polls"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "_release", "gripper polls"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "is_grasping", "gripper polls"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "width", "gripper polls"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "fraction", "gripper polls"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "set_fraction", "gripper commands"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "set_force", "gripper commands"),
    ("robocfg.sim.gripper.parallel", "ParallelGripper", "reset", "gripper commands"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "_support_height", "support ray casts"),
    ("robocfg.engine.session", "EpisodeSession", "_reset", "world restore"),
    ("robocfg.sim.world", "World", "add_body", "object spawn"),
    ("robocfg.runners.pick_place", None, "episode_setup", "episode set-up"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "__init__", "episode set-up"),
    ("robocfg.sim.robot", "RobotHandle", "link_pose", "state reads"),
    ("robocfg.sim.robot", "RobotHandle", "link_position_quat", "state reads"),
    ("robocfg.sim.robot", "RobotHandle", "joint_positions", "state reads"),
    ("robocfg.sim.world", "World", "body_pose", "state reads"),
    ("robocfg.runners.pick_place_machine", "_StateMachine", "result", "episode record"),
)


_INHERITED = object()  # a wrapped attribute that its holder inherited (uninstall deletes it)


class Meter:
    """CPU seconds per label, **exclusive**: a wrapped call charges its label with its CPU time
    minus that of the wrapped calls inside it, which charge theirs (the stack's top is charged;
    the episode itself is the bottom, ``other``). ``stepSimulation`` and the bucket functions are
    wrapped. ``calls[label]``: timed calls of the label; ``inner[label]``: wrapped calls made
    while it was on top (each leaves part of the wrapper's own cost in it)."""

    def __init__(self) -> None:
        self.acc: dict[str, float] = defaultdict(float)
        self.calls: dict[str, int] = defaultdict(int)
        self.inner: dict[str, int] = defaultdict(int)
        self._stack: list[str] = ["other"]
        self._mark = time.process_time()
        self.cost_in = self.cost_out = 0.0  # s per call, from calibrate()
        self._wrapped: list[tuple[Any, str, Any, Any, str]] = []  # (holder, name, its own attribute, function, label)

    def timed(self, f: Any, label: str) -> Any:
        stack, acc, calls, inner, clock = self._stack, self.acc, self.calls, self.inner, time.process_time

        def timed(*a: Any, **k: Any) -> Any:  # one clock reading at each end: every µs lands in some label
            t = clock()
            top = stack[-1]
            acc[top] += t - self._mark
            self._mark = t
            inner[top] += 1
            stack.append(label)
            try:
                return f(*a, **k)
            finally:
                t = clock()
                acc[label] += t - self._mark
                self._mark = t
                calls[label] += 1
                stack.pop()

        return timed

    def wrap(self, holder: Any, name: str, label: str) -> None:
        self._wrapped.append((holder, name, vars(holder).get(name, _INHERITED), getattr(holder, name), label))

    def install(self, physics_only: bool = False) -> None:
        """Wrap ``stepSimulation`` and the buckets' functions (again, after ``uninstall``);
        ``physics_only``: ``stepSimulation`` alone."""
        import pybullet

        if not self._wrapped:
            self.wrap(pybullet, "stepSimulation", "stepSimulation")
            for mod, cls, fn, label in BUCKETS:
                m = importlib.import_module(mod)
                holder = m if cls is None else getattr(m, cls)
                if hasattr(holder, fn):  # (an older version of the code, measured for comparison, may lack it)
                    self.wrap(holder, fn, label)
        for holder, name, _, f, label in self._wrapped:
            if physics_only and label != "stepSimulation":
                continue
            setattr(holder, name, self.timed(f, label))

    def uninstall(self) -> None:
        """Put the functions back as they were: episodes run without any timer."""
        for holder, name, own, _, _ in reversed(self._wrapped):
            if own is _INHERITED:
                if name in vars(holder):
                    delattr(holder, name)
            else:
                setattr(holder, name, own)

    def calibrate(self, n: int = 20000, repeats: int = 5) -> None:
        """The wrapper's own CPU per call (medians of ``repeats``), measured on PyBullet's
        cheapest call made as robocfg calls ``stepSimulation`` (a keyword client id): the part
        charged to the called label (``cost_in``) and the part charged to the caller's (``cost_out``)."""
        import pybullet

        client = pybullet.connect(pybullet.DIRECT)
        f = pybullet.getNumBodies
        noop = self.timed(f, "_calibration")
        inside, outside = [], []
        try:
            for _ in range(repeats):
                self.acc["_calibration"] = self.acc["_caller"] = 0.0
                self._stack.append("_caller")
                self._mark = time.process_time()
                for _ in range(n):
                    noop(physicsClientId=client)
                self.acc["_caller"] += time.process_time() - self._mark
                self._stack.pop()
                c0 = time.process_time()
                for _ in range(n):
                    f(physicsClientId=client)
                c1 = time.process_time()
                for _ in range(n):
                    pass
                loop = (time.process_time() - c1) / n
                call = (c1 - c0) / n - loop  # the call itself
                inside.append(self.acc["_calibration"] / n - call)
                outside.append(self.acc["_caller"] / n - loop)
        finally:
            pybullet.disconnect(client)
        self.cost_in, self.cost_out = st.median(inside), st.median(outside)
        for d in (self.acc, self.calls, self.inner):
            for key in ("_calibration", "_caller"):
                d.pop(key, None)
        self._mark = time.process_time()

    def snapshot(self) -> dict[str, float]:
        """CPU s per label with the timers' cost removed from where it fell, and ``_timers``: the
        CPU s the timers cost (``other`` is charged up to now)."""
        t = time.process_time()
        self.acc[self._stack[-1]] += t - self._mark
        self._mark = t
        out = {k: v - self.calls[k] * self.cost_in - self.inner[k] * self.cost_out for k, v in self.acc.items()}
        out["_timers"] = sum(self.calls.values()) * (self.cost_in + self.cost_out)
        return out


def _task(name: str):
    from robocfg.checks import load_task
    from robocfg.config import catalog

    t = load_task(catalog.find("tasks", name))
    return dataclasses.replace(t, config=t.config.model_copy(update={"cameras": []}))


def _time_physics(session: Any, on: bool) -> None:
    """The world's own physics clock (``World.time_physics``, two ``perf_counter`` calls a step) on
    or off: on in the untimed run only (its wall-clock cross-check reads it), off in the others, as
    robocfg runs by default (``RunOptions.time_physics``)."""
    if hasattr(session.options, "time_physics"):  # (code from before the option: its clock always runs)
        session.options = dataclasses.replace(session.options, time_physics=on)  # a world built anew takes it too
    session.world.time_physics = on


def _episode(session: Any, k: int, meter: Meter) -> tuple[float, dict[str, float]]:
    """(episode CPU s, {label: CPU s} with ``calls:<label>``: the label's timed calls)."""
    calls0 = dict(meter.calls)
    before, c0 = meter.snapshot(), time.process_time()
    session.run(k)
    cpu = time.process_time() - c0
    after = meter.snapshot()
    out = {key: after.get(key, 0.0) - before.get(key, 0.0) for key in after}
    return cpu, out | {f"calls:{key}": float(n - calls0.get(key, 0)) for key, n in meter.calls.items()}


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
    untimed: list[float] = []
    walls: list[tuple[float, float]] = []
    physics_runs: list[tuple[float, dict[str, float]]] = []
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
        meter.uninstall()
        for k in range(1, args.episodes + 1):
            # Episode k three ways, in turn (the order rotates with k): every bucket timed, only
            # stepSimulation timed (the physics, with the fewest timers), no timer at all (the CPU).
            for way in (("buckets", "physics", "untimed") * 2)[k % 3:k % 3 + 3]:
                if way == "untimed":
                    _time_physics(sessions["none"], True)  # the world's own physics clock, for the cross-check
                    c0 = time.process_time()
                    sessions["none"].run(k)
                    untimed.append(time.process_time() - c0)
                    _time_physics(sessions["none"], False)
                    timing = sessions["none"].timing  # the world's own wall clock: the episode, its physics
                    walls.append((timing.per_episode[-1], timing.physics_per_episode[-1]))
                    continue
                meter.install(physics_only=way == "physics")
                if way == "physics":
                    physics_runs.append(_episode(sessions["none"], k, meter))
                else:
                    for key, session in sessions.items():
                        runs[key].append(_episode(session, k, meter))
                meter.uninstall()
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

    def own_of(run: tuple[float, dict[str, float]]) -> float:  # (episode CPU − timers − physics) ÷ physics
        c, b = run
        return (c - b["_timers"] - b["stepSimulation"]) / b["stepSimulation"]

    phys = [b["stepSimulation"] for _, b in physics_runs]
    # The headline: the physics-only run, one timer a physics step, its calibrated cost removed.
    own = med([own_of(r) for r in physics_runs])
    # The untimed run's CPU minus the physics of the physics-only run of the same episode: no timer
    # in it, but a difference of two runs (under load their CPU per step can differ by 10-20 %).
    own_paired = med([(u - ph) / ph for u, ph in zip(untimed, phys, strict=True)])
    physics, cpu = med(phys), med([c - b["_timers"] for c, b in physics_runs])
    labels = list(dict.fromkeys(label for *_, label in BUCKETS))
    buckets = {label: med([b.get(label, 0.0) for _, b in none]) for label in labels}
    calls = {label: med([b.get(f"calls:{label}", 0.0) for _, b in none]) for label in labels}
    other = med([b.get("other", 0.0) for _, b in none])
    phys_buckets = med([b["stepSimulation"] for _, b in none])

    def net(run: tuple[float, dict[str, float]]) -> float:  # an episode's CPU without the benchmark's timers
        return run[0] - run[1].get("_timers", 0.0)

    cost = {f: med([net(d) / net(n) for n, d in zip(none, runs[f], strict=True)]) for f in formats}
    res = {"task": args.task, "episodes": args.episodes, "cpu_per_episode_ms": round(cpu * 1e3, 2),
           "physics_per_episode_ms": round(physics * 1e3, 2), "own_share_of_physics": round(own, 3),
           "own_share_untimed_minus_physics": round(own_paired, 3),
           "cpu_per_episode_untimed_ms": round(med(untimed) * 1e3, 2),
           "own_share_wall_untimed": round(med([(w - ph) / ph for w, ph in walls]), 3),
           "own_share_bucket_run": round(med([own_of(r) for r in none]), 3),
           "physics_bucket_run_ms": round(phys_buckets * 1e3, 2),
           "buckets_ms": {k: round(v * 1e3, 2) for k, v in buckets.items()},
           "calls_per_episode": {k: round(v) for k, v in calls.items()},
           "other_ms": round(other * 1e3, 2),
           "timer_overhead_ms": {"physics_run": round(med([b["_timers"] for _, b in physics_runs]) * 1e3, 2),
                                 "bucket_run": round(med([b["_timers"] for _, b in none]) * 1e3, 2)},
           "timer_cost_us": {"inside": round(meter.cost_in * 1e6, 3), "outside": round(meter.cost_out * 1e6, 3)},
           "state_only_dataset_cost": {f: round(c, 3) for f, c in cost.items()},
           "dataset_cpu_per_episode_ms": {f: round(med([net(r) for r in runs[f]]) * 1e3, 2) for f in formats},
           "fixed_ms": {f: round(v * 1e3, 1) for f, v in fixed.items()}}
    print(f"{args.task}: {cpu * 1e3:.1f} ms CPU per episode, {physics * 1e3:.1f} ms in stepSimulation; robocfg's own "
          f"work {own:.1%} of physics (median over episodes 1..{args.episodes}, the physics-only run: one timer a "
          f"step, {res['timer_overhead_ms']['physics_run']:.1f} ms an episode by calibration removed; what a timer costs "
          f"beyond that in situ stays in, so this reads a little high)")
    print(f"  cross-checks: {res['own_share_wall_untimed']:.1%} by the world's own wall clock in the untimed run "
          f"(episode − time inside stepSimulation, ÷ the latter; no timer, preemption falls in both); "
          f"{own_paired:.1%} as untimed CPU − the physics-only run's physics (no timer, but two runs: noisy under load); "
          f"{res['own_share_bucket_run']:.1%} from the bucketed run (its timers, {res['timer_overhead_ms']['bucket_run']:.1f} ms "
          f"an episode at {meter.cost_in * 1e6:.2f} + {meter.cost_out * 1e6:.2f} µs a call by calibration, removed)")
    print(f"  buckets of the bucketed run (exclusive; physics there {phys_buckets * 1e3:.1f} ms):")
    for label, v in sorted(buckets.items(), key=lambda kv: -kv[1]):
        print(f"  {label:26s} {v * 1e3:7.2f} ms  {v / phys_buckets:6.1%} of physics  ({calls[label]:.0f} calls)")
    print(f"  {'other':26s} {other * 1e3:7.2f} ms  {other / phys_buckets:6.1%} of physics")
    for f in formats:
        print(f"state-only {f} dataset: {cost[f]:.3f}x the CPU of the same episode without (median of per-episode "
              f"ratios); once per run: {res['fixed_ms'][f]:.1f} ms (writer opened incl. first imports, and closed)")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
