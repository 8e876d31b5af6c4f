"""Grasp-from-depth benchmark: lift success over the shape set and grasp planning time, per robot.

    python benchmarks/bench_grasp.py --episodes 100 [--robots panda,ur5e_robotiq_2f85] [--seed 0] [--json out.json]

Episode k grasps ``objects[k % 9]`` of the built-in ``grasp`` task (boxes at random yaw, standing and lying
cylinders, a sphere, pybullet_data meshes) at a random spot; success = held after a 15 cm lift and
a ±4 cm shake, within ``max_attempts`` (3) grasps. Planning time = one plan: antipodal sampling,
scoring, collision checks and IK reachability (the rendering and cloud processing are reported
apart as perception). Robots that are not installed are skipped. Goals (issue 9): ≥ 95 % on
Panda, ≥ 90 % on UR5e + 2F-85, median planning ≤ 0.8 s (Dex-Net 2.0 reports 0.8 s).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robots", default="panda,ur5e_robotiq_2f85")
    ap.add_argument("--task", default="grasp")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.errors import NotFound
    from robocfg.runners.grasp import run_grasp

    rows, out = [], {}
    for robot in args.robots.split(","):
        try:
            task = load_task(catalog.find("tasks", args.task), robot_override=robot)
        except NotFound:
            print(f"skipping {robot}: not installed")
            continue
        t0 = time.perf_counter()
        report, timing = run_grasp(task, episodes=args.episodes, seed=args.seed)
        wall = time.perf_counter() - t0
        s = report.summary
        plan = np.asarray(timing.planning)
        rows.append((robot, s.episodes, f"{s.success_rate:.1%}", f"{s.first_attempt_rate:.1%}", f"{s.mean_attempts:.2f}",
                     f"{np.median(plan):.3f}", f"{np.percentile(plan, 90):.3f}", f"{timing.median_perception:.3f}",
                     f"{wall / s.episodes:.2f}"))
        out[robot] = {"summary": s.__dict__, "planning_s": {"median": float(np.median(plan)),
                                                           "p90": float(np.percentile(plan, 90)), "n": len(plan)},
                      "perception_s_median": timing.median_perception, "wall_s_per_episode": wall / s.episodes,
                      "failures": [{"episode": e.index, "object": e.object, "phase": e.failed_phase, "reason": e.reason}
                                   for e in report.episodes if not e.success]}
        print(f"{robot}: by object {s.by_object}; failures by phase {s.failures_by_phase}")
    head = ("robot", "episodes", "lift success", "1st attempt", "attempts", "plan med (s)", "plan p90 (s)",
            "perception med (s)", "wall/episode (s)")
    widths = [max(len(h), *(len(str(r[i])) for r in rows)) if rows else len(h) for i, h in enumerate(head)]
    print("  ".join(h.ljust(w) for h, w in zip(head, widths, strict=True)))
    for r in rows:
        print("  ".join(str(v).ljust(w) for v, w in zip(r, widths, strict=True)))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2, default=str)


if __name__ == "__main__":
    main()
