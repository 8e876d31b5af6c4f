"""Trajectory timing, side by side in one run, on the Panda with the default task's limits:

* ours — ``plan_trajectory`` (toppra on the spline, ~100 gridpoints, uniform fit; or the
  stop-at-waypoint trapezoids when those are faster);
* optimum — toppra at 1000 gridpoints on the same spline, no fit (the reference optimum);
* stop — one synchronised trapezoid per segment, at rest at every waypoint (Isaac Sim's
  ``to_minimal_time_joint_trajectory`` semantics).

Paths: home → reach-out → home (the built-in ``trajectory`` task); a 6-waypoint "via-point"
route (waypoints on a curved joint-space route, as a motion planner outputs them); a 6-waypoint
zig-zag (random waypoints in a box around home, seed 0: joints reverse at most waypoints).
Also: planning time (first call in the process and median of warm calls), limit violations
resampled at 1 kHz, and Panda tracking in PyBullet (RMS and final error, our follower vs the naive
"command the next sample" follower).

    python benchmarks/bench_trajectory.py [--task robocfg/data/tasks/trajectory.yaml] [--repeats 20] [--scale S] [--json out.json]

Goals: ours within 2 % of the optimum; ≥ 25 % shorter than stop on the 6-waypoint via-point path;
planning ≤ 20 ms; 0 violations; tracking RMS ≤ 0.005 rad and final error ≤ 0.002 rad.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def paths(seed: np.ndarray) -> dict[str, np.ndarray]:
    """The seed task's resolved waypoints, and two 6-waypoint paths around its first waypoint."""
    home = seed[0]
    u = np.linspace(0.0, 1.0, 6)[:, None]
    via = (home + u * np.array([1.6, 0.4, 0.3, 0.6, 0.4, 0.3, -0.5])
           + np.sin(np.pi * u) * np.array([0.0, 0.5, -0.4, 0.4, 0.0, 0.3, 0.0]))
    rng = np.random.default_rng(0)
    zig = home + rng.uniform(-0.5, 0.5, size=(6, 7))
    zig[0] = home
    return {f"seed ({len(seed)} wp)": seed, "via-point (6 wp)": via, "zig-zag (6 wp)": zig}


def track(task, names, traj, mode: str) -> tuple[float, float]:
    from robocfg.motion.follower import follow
    from robocfg.sim.world import World

    with World(task) as world:
        q0 = traj.evaluate(0.0)[0][0]
        world.robot.reset_joints(names, q0)
        world.robot.command_positions(names, q0)
        tr = follow(world, names, traj, settle_time=0.0, mode=mode)
    return tr.rms, tr.final


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--task", default=str(ROOT / "robocfg/data/tasks/trajectory.yaml"))
    ap.add_argument("--repeats", type=int, default=20)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--scale", type=float, default=None,
                    help="Override the task's velocity_scale and acceleration_scale (e.g. 1.0 for the full limits).")
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.motion.limits import limits_from_robot
    from robocfg.motion.path import smooth_path
    from robocfg.motion.plan import load_libraries, plan_trajectory
    from robocfg.motion.timing import time_optimal
    from robocfg.motion.trajectory import check_limits
    from robocfg.motion.trapezoid import stop_at_waypoints
    from robocfg.runners.trajectory import plan_task

    task = load_task(args.task)
    params = task.config.trajectory
    robot = task.robots[0]
    arm = robot.config.arm(params.arm)
    names = robot.arm_joints(arm)
    lim_params = params.limits
    if args.scale is not None:
        lim_params = lim_params.model_copy(update={"velocity_scale": args.scale, "acceleration_scale": args.scale})
    limits = limits_from_robot(robot, names, lim_params)
    t_import = time.perf_counter()
    load_libraries()
    t_import = time.perf_counter() - t_import
    seed = plan_task(task)[4].q  # the task's waypoints in joint space (IK for Cartesian ones)

    rows = []
    first = True
    for name, W in paths(seed).items():
        t0 = time.perf_counter()
        plan = plan_trajectory(W, limits)
        cold = (time.perf_counter() - t0) * 1e3
        warm, cpu = [], []
        for _ in range(args.repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            plan_trajectory(W, limits)
            warm.append((time.perf_counter() - t0) * 1e3)
            cpu.append((time.process_time() - c0) * 1e3)
        path = smooth_path(W, limits.lower, limits.upper, limits.bounded())
        t0 = time.perf_counter()
        opt = time_optimal(path, limits, gridpoints=1000, fit=False)
        t_opt = (time.perf_counter() - t0) * 1e3
        stop = stop_at_waypoints(W, limits)
        ours_check = check_limits(plan.trajectory, limits, 1000.0)
        opt_check = check_limits(opt, limits, 1000.0)
        rms, final = track(task, names, plan.trajectory, "matched")
        rms_naive, final_naive = track(task, names, plan.trajectory, "next")
        rows.append({
            "path": name, "method": f"{plan.method}/{plan.path}", "gridpoints": plan.gridpoints,
            "ours_s": plan.duration, "optimum_s": opt.duration, "stop_s": stop.duration,
            "vs_optimum_pct": 100 * (plan.duration / opt.duration - 1),
            "vs_stop_pct": 100 * (1 - plan.duration / stop.duration),
            "plan_ms_first": cold, "plan_ms_min": min(warm), "plan_ms_median": statistics.median(warm), "plan_ms_max": max(warm),
            "plan_cpu_ms_median": statistics.median(cpu),
            "optimum_ms": t_opt, "violations_1khz": ours_check.total, "optimum_violations_1khz": opt_check.total,
            "peak_v_ratio": ours_check.peak_velocity_ratio, "peak_a_ratio": ours_check.peak_acceleration_ratio,
            "track_rms_rad": rms, "track_final_rad": final, "naive_rms_rad": rms_naive, "naive_final_rad": final_naive,
            "first_in_process": first,
        })
        first = False

    from rich.console import Console
    from rich.table import Table

    lim = f"v = {np.round(limits.velocity, 3).tolist()} rad/s, a = {np.round(limits.acceleration, 2).tolist()} rad/s²"
    t = Table(title=f"run trajectory timing — Panda, {lim}")
    for col in ("path", "method", "ours (s)", "optimum 1000 gp (s)", "stop (s)", "vs optimum", "shorter than stop",
                "plan ms wall (first / min / median / max)", "plan ms CPU (median)", "1000 gp ms", "violations @1 kHz (ours / opt)",
                "tracking RMS / final (rad)", "naive follower RMS / final"):
        t.add_column(col)
    for r in rows:
        t.add_row(r["path"], r["method"], f"{r['ours_s']:.4f}", f"{r['optimum_s']:.4f}", f"{r['stop_s']:.4f}",
                  f"{r['vs_optimum_pct']:+.2f} %", f"{r['vs_stop_pct']:.1f} %",
                  f"{r['plan_ms_first']:.1f} / {r['plan_ms_min']:.1f} / {r['plan_ms_median']:.1f} / {r['plan_ms_max']:.1f}",
                  f"{r['plan_cpu_ms_median']:.1f}", f"{r['optimum_ms']:.0f}",
                  f"{r['violations_1khz']} / {r['optimum_violations_1khz']}",
                  f"{r['track_rms_rad']:.1e} / {r['track_final_rad']:.1e}",
                  f"{r['naive_rms_rad']:.1e} / {r['naive_final_rad']:.1e}")
    Console(width=250).print(t)
    print(f"load average at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs (wall times grow with it)")
    print(f"library import (toppra + scipy, once per process): {t_import * 1e3:.0f} ms; "
          f"'first' planning time is the first call in the process after the import")
    if args.json:
        args.json.write_text(json.dumps({"limits": {"velocity": limits.velocity.tolist(),
                                                    "acceleration": limits.acceleration.tolist()},
                                         "import_ms": t_import * 1e3, "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
