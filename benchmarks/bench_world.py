"""Steps per second of ``World.step()`` (holding the robot at home) vs a bare ``p.stepSimulation()``
loop on the same scene, in one run; plus the whole-process time of ``robocfg run gripper``.

    python benchmarks/bench_world.py [--task robocfg/data/tasks/gripper.yaml] [--steps 4800] [--chunk 120] [--json out.json]

Both loops run in the same World (same robot, drives, mimic gears, objects), interleaved in chunks
of ``--chunk`` steps so that load from other processes hits both alike; the overhead is the median
of the per-chunk time ratios, the rates are totals. Goal: our overhead ≤ 10 %.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def bench_steps(task_path: Path, steps: int, chunk: int) -> dict:
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import pybullet as p

    from robocfg.checks import load_task
    from robocfg.sim.world import World

    task = load_task(task_path)
    bare, ours, ratios = 0.0, 0.0, []
    with World(task) as w:
        c = w.client
        w.step(240)  # settle
        for _ in range(max(1, steps // chunk)):
            t0 = time.perf_counter()
            for _ in range(chunk):
                p.stepSimulation(physicsClientId=c)
            t1 = time.perf_counter()
            w.step(chunk)
            t2 = time.perf_counter()
            bare, ours = bare + (t1 - t0), ours + (t2 - t1)
            ratios.append((t2 - t1) / (t1 - t0))
        drift = float(abs(w.robot.arm().joint_positions() - w.robot.arm().home).max())
    n = max(1, steps // chunk) * chunk
    ratios.sort()
    return {"robot": task.robots[0].config.name, "dt": task.config.sim.timestep, "steps": n, "chunk": chunk,
            "bare_steps_per_s": n / bare, "world_steps_per_s": n / ours,
            "overhead": ratios[len(ratios) // 2] - 1.0, "home_drift_rad": drift}


def bench_process(args: list[str], repeats: int = 2) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", "from robocfg.cli.app import main; main()", *args],
                             cwd=ROOT, capture_output=True, text=True)
        if out.returncode != 0:
            raise SystemExit(f"robocfg {' '.join(args)} failed: {out.stderr}")
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", type=Path, default=ROOT / "robocfg" / "data" / "tasks" / "gripper.yaml")
    ap.add_argument("--steps", type=int, default=4800)
    ap.add_argument("--chunk", type=int, default=120)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--no-process", action="store_true", help="skip the whole-process timings")
    a = ap.parse_args()
    r = bench_steps(a.task, a.steps, a.chunk)
    print(f"World.step vs bare stepSimulation — {r['robot']}, dt {r['dt']:.5f} s, {r['steps']} steps each, "
          f"interleaved in chunks of {r['chunk']}")
    print(f"{'loop':<28}{'steps/s':>10}{'× real time':>14}")
    for key, label in (("bare_steps_per_s", "bare p.stepSimulation"), ("world_steps_per_s", "World.step (checks+grippers)")):
        print(f"{label:<28}{r[key]:>10.0f}{r[key] * r['dt']:>14.1f}")
    print(f"{'overhead':<28}{r['overhead'] * 100:>9.1f} %   (median per-chunk, goal ≤ 10 %)   home drift {r['home_drift_rad']:.1e} rad")
    if not a.no_process:
        r["process_run_gripper_s"] = bench_process(["run", "gripper", "-q"])
        r["process_run_gripper_gif_s"] = bench_process(["run", "gripper", "-q", "--record", "/tmp/robocfg_bench.gif"], 1)
        r["process_help_s"] = bench_process(["--help"])
        print(f"{'whole process':<28}{'seconds':>10}")
        for key, label in (("process_help_s", "robocfg --help"), ("process_run_gripper_s", "robocfg run gripper -q"),
                           ("process_run_gripper_gif_s", "… --record out.gif")):
            print(f"{label:<28}{r[key]:>10.2f}")
    if a.json:
        a.json.write_text(json.dumps(r, indent=2) + "\n")


if __name__ == "__main__":
    main()
