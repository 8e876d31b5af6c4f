"""What a physics step costs robocfg besides ``stepSimulation``, against the floor: a bare Python
loop of one ``setJointMotorControlArray`` (the same arguments, its rows ready-made lists) and one
``stepSimulation`` a step.

    python benchmarks/bench_step_loop.py [--task pick_place] [--steps 1200] [--rounds 20] [--base DIR]
    python benchmarks/bench_step_loop.py --callgrind [--base DIR]
    python benchmarks/bench_step_loop.py --callgrind --episodes 3

With ``--episodes N`` (callgrind only): whole episodes 1..N of the task (seed 0) after a warm-up
instead, the instructions an episode outside ``stepSimulation`` and inside it.

On the task's world (episode 0 run, then restored: the arm at home), the same smooth move of
``--steps`` rows away from home is played from one saved state by each variant in turn, the order
reversed every other round:

* ``floor`` — the bare loop above;
* ``play`` — ``World.play`` (:mod:`robocfg.sim.playback`'s bare loop, as a move plays);
* ``base play`` — with ``--base DIR``: ``DIR/robocfg/sim/playback.py``'s ``_play_bare`` (an older
  checkout's, e.g. ``git archive <commit> robocfg | tar -x -C DIR``) on the same rows;
* ``idle floor`` / ``idle`` — ``--steps`` bare ``stepSimulation`` calls / ``World.step(steps)``;
* ``checks`` — the divergence check (``World._check``) 100 times, per check.

The loops run without their periodic divergence check (measured apart, ``checks``) and without the
world's physics clock (``World.time_physics`` off, as robocfg runs by default). CPU (default): per
variant the main thread's CPU minus the CPU inside ``stepSimulation`` (one timer a step, the same
in every variant), µs a step: medians over the rounds and the paired differences. ``--callgrind``:
the script runs itself under ``valgrind --tool=callgrind`` with the counts dumped around each
variant (one round): instructions a step outside ``stepSimulation``, the same whatever the load.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import shutil
import statistics as st
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _variants(task_name: str, steps: int, base: Path | None) -> dict[str, Callable[[], None]]:
    """The variants (module docstring), each a call that plays from the world's saved state."""
    sys.path.insert(0, str(HERE))
    from bench_control_swap import _task

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import numpy as np
    import pybullet as p

    from robocfg.engine import RunOptions, open_session

    session = open_session(_task(task_name), RunOptions(seed=0))
    session.run(0)
    session._reset()
    w = session.world
    w.time_physics = False
    w.periodic_check = lambda: None  # type: ignore[method-assign]
    arm = w.robot.arm()
    q0 = arm.joint_positions()
    s = np.arange(1, steps + 1) / steps
    ramp = 0.3 * s**3 * (10 - 15 * s + 6 * s**2)
    slope = 0.3 * 30 * s**2 * (1 - s) ** 2 / (steps * w.dt)
    reach = np.linspace(0.3, 1.0, len(q0))
    q, qd = q0 + np.outer(ramp, reach), np.outer(slope, reach)
    rows, speeds = q.tolist(), qd.tolist()
    plan = arm.robot.motor_plan(tuple(arm.joints))
    assert plan is not None
    _, idx, kp, kd, force, _ = plan
    body, client, mode = arm.robot.body_id, w.client, p.POSITION_CONTROL
    state = p.saveState(physicsClientId=client)

    def restored(f: Callable[[], None]) -> Callable[[], None]:
        def run() -> None:
            p.restoreState(state, physicsClientId=client)
            w.steps, w.t = 0, 0.0
            f()
        return run

    def floor() -> None:
        send, stepsim = p.setJointMotorControlArray, p.stepSimulation
        for row, v in zip(rows, speeds, strict=True):
            send(body, idx, mode, row, v, force, kp, kd, client)
            stepsim(client)

    def idle_floor() -> None:
        stepsim = p.stepSimulation
        for _ in range(steps):
            stepsim(client)

    def checks() -> None:
        for _ in range(100):
            w._check()

    out = {"floor": floor, "play": lambda: w.play(arm, q, qd)}
    if base is not None:
        spec = importlib.util.spec_from_file_location("base_playback", base / "robocfg" / "sim" / "playback.py")
        assert spec is not None and spec.loader is not None
        old = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(old)
        out["base play"] = lambda: old._play_bare(w, arm, plan, q, qd)
    out |= {"idle floor": idle_floor, "idle": lambda: w.step(steps), "checks": checks}
    return {k: restored(f) for k, f in out.items()}


def cpu(args: argparse.Namespace) -> None:
    variants = _variants(args.task, args.steps, args.base)
    import pybullet as p

    inside = [0.0]
    stepsim, clock = p.stepSimulation, time.thread_time

    def timed(*a: object, **k: object) -> object:
        t = clock()
        try:
            return stepsim(*a, **k)
        finally:
            inside[0] += clock() - t

    p.stepSimulation = timed
    own: dict[str, list[float]] = {k: [] for k in variants}
    names = list(variants)
    for r in range(args.rounds):
        for name in names if r % 2 == 0 else names[::-1]:
            inside[0] = 0.0
            t = clock()
            variants[name]()
            own[name].append((clock() - t - inside[0]) / (100 if name == "checks" else args.steps) * 1e6)
    print(f"{args.task}, {args.steps} steps a variant, {args.rounds} rounds (load {os.getloadavg()[0]:.1f}): "
          "main-thread CPU outside stepSimulation, µs a step (checks: a check), median")
    for name, v in own.items():
        print(f"  {name:12s} {st.median(v):8.3f}")
    pairs = [("play", "floor"), ("idle", "idle floor")] + ([("base play", "play"), ("base play", "floor")]
                                                           if args.base is not None else [])
    for a, b in pairs:
        d = [x - y for x, y in zip(own[a], own[b], strict=True)]
        q1, _, q3 = st.quantiles(d, n=4)
        print(f"  {a} - {b}: paired {st.median(d):.3f} µs a step (quartiles {q1:.3f}..{q3:.3f})")


def _episodes(task_name: str, n: int) -> dict[str, Callable[[], None]]:
    """Episodes 1..n of the task after a warm-up, as one variant."""
    sys.path.insert(0, str(HERE))
    from bench_control_swap import _task

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.engine import RunOptions, open_session

    session = open_session(_task(task_name), RunOptions(seed=0))
    session.run(0)
    return {"episodes": lambda: [session.run(k) for k in range(1, n + 1)] and None}


def child(args: argparse.Namespace) -> None:
    variants = {"null": lambda: None} | (_episodes(args.task, args.episodes) if args.episodes
                                         else _variants(args.task, args.steps, args.base))
    pid = str(os.getpid())

    def control(*a: str) -> None:
        subprocess.run(["callgrind_control", *a, pid], check=True, capture_output=True)

    control("-i", "on")
    for name, f in variants.items():
        control("-d", "before")
        f()
        control("-d", name.replace(" ", "_"))


def callgrind(args: argparse.Namespace) -> int:
    if shutil.which("valgrind") is None:
        print("valgrind is needed: nothing counted")
        return 2
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "cg.out"
        cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", f"--callgrind-out-file={out}", sys.executable,
               __file__, "--child", "--task", args.task, "--steps", str(args.steps), "--episodes", str(args.episodes)]
        if args.base is not None:
            cmd += ["--base", str(args.base)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            print(p.stderr[-3000:])
            return 1
        counts: dict[str, float] = {}
        physics: dict[str, int] = {}
        for dump in Path(d).glob("cg.out.*"):
            text = dump.read_text(errors="replace")
            name = re.search(r"^desc: Trigger: .*dump (\S+)", text, re.M)
            if name is None or name.group(1) == "before":
                continue
            total = int(re.search(r"^totals: (\d+)", text, re.M).group(1))  # type: ignore[union-attr]
            ann = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(dump)],
                                 capture_output=True, text=True, check=True).stdout
            m = re.search(r"^\s*([\d,]+) .*pybullet_stepSimulation \[", ann, re.M)
            physics[name.group(1).replace("_", " ")] = int(m.group(1).replace(",", "")) if m else 0
            counts[name.group(1).replace("_", " ")] = total - physics[name.group(1).replace("_", " ")]
    null = counts.pop("null")
    if args.episodes:
        print(f"{args.task}, episodes 1..{args.episodes} after a warm-up (callgrind), an episode: "
              f"{(counts['episodes'] - null) / args.episodes / 1e6:.2f} M instructions outside stepSimulation, "
              f"{physics['episodes'] / args.episodes / 1e6:.2f} M inside")
        return 0
    print(f"{args.task}, {args.steps} steps a variant (callgrind): instructions outside stepSimulation, a step "
          "(checks: a check; the dump's own cost, the 'null' variant, removed)")
    order = ["floor", "play", "base play", "idle floor", "idle", "checks"]
    for name in sorted(counts, key=lambda k: order.index(k) if k in order else len(order)):
        print(f"  {name:12s} {(counts[name] - null) / (100 if name == 'checks' else args.steps):10.0f}")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--steps", type=int, default=1200)
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--base", type=Path, default=None, help="an older checkout (a folder holding robocfg/)")
    ap.add_argument("--callgrind", action="store_true")
    ap.add_argument("--episodes", type=int, default=0, help="with --callgrind: whole episodes 1..N instead")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        child(args)
        return 0
    if args.callgrind:
        return callgrind(args)
    cpu(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
