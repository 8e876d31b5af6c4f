"""Pick-place success rate and speed, side by side with a bare physics loop on the same scene.

    python benchmarks/bench_pick_place.py --episodes 200 [--robot panda] [--task pick_place] [--json out.json]

Rows: the task as shipped, and the same with ±10 % mass and friction randomisation. The reference
row steps the same world (robot at home + the object) with nothing but ``p.stepSimulation`` for
as many steps as an average episode, so the ratio is the cost of everything we add (world
bookkeeping, IK, planning, drives, checks) per simulated step.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np


def bare_loop_seconds(task, steps: int, repeats: int = 15) -> float:
    """Wall time of ``steps`` bare ``stepSimulation`` calls on the task's world with its object
    (median of ``repeats`` runs: one run is ~0.1 s and noisy on a shared machine)."""
    import pybullet as p

    from robocfg.sim.world import World

    with World(task) as world:
        world.add_body(task.config.pick_place.object)
        c = world.client
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            for _ in range(steps):
                p.stepSimulation(physicsClientId=c)
            times.append(time.perf_counter() - t0)
        return float(np.median(times))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robot", default=None)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.engine import RunOptions, run

    base = load_task(catalog.find("tasks", args.task), robot_override=args.robot)
    rz = base.config.pick_place.randomize
    varied_params = base.config.pick_place.model_copy(
        update={"randomize": rz.model_copy(update={"mass_scale": 0.1, "friction_scale": 0.1})})
    varied = type(base)(base.config.model_copy(update={"pick_place": varied_params}), base.doc, base.robots)
    rows = []
    for label, task in (("as shipped", base), ("±10 % mass & friction", varied)):
        out = run(task, RunOptions(seed=args.seed, episodes=args.episodes, time_physics=True))  # physics timed
        report, timing = out.report, out.timing
        steps = float(np.mean([e.steps for e in report.episodes]))
        bare = bare_loop_seconds(task, round(steps))
        per_ep = timing.mean_episode
        physics = timing.mean_physics
        rows.append({
            "variant": label, "episodes": report.summary.episodes, "success_rate": report.summary.success_rate,
            "failures_by_phase": report.summary.failures_by_phase, "mean_sim_time_s": report.summary.mean_sim_time,
            "mean_steps": steps, "wall_per_episode_s": per_ep, "bare_physics_same_steps_s": bare,
            "ratio_to_bare": per_ep / bare if bare > 0 else float("nan"),
            "physics_in_run_s": physics, "control_overhead": (per_ep - physics) / physics if physics > 0 else float("nan"),
        })
    robot = base.robots[0].config.name
    print(f"pick-place benchmark: robot {robot}, task {args.task}, {args.episodes} episodes, seed {args.seed}")
    head = (f"{'variant':<24}{'success':>10}{'failures':>16}{'sim s/ep':>10}{'wall s/ep':>11}{'bare s':>9}"
            f"{'ratio':>7}{'physics s':>11}{'control':>9}")
    print(head)
    print("-" * len(head))
    for r in rows:
        fails = ", ".join(f"{k}:{v}" for k, v in r["failures_by_phase"].items()) or "none"
        print(f"{r['variant']:<24}{r['success_rate']:>9.1%} {fails:>15}{r['mean_sim_time_s']:>10.2f}"
              f"{r['wall_per_episode_s']:>11.3f}{r['bare_physics_same_steps_s']:>9.3f}{r['ratio_to_bare']:>7.2f}"
              f"{r['physics_in_run_s']:>11.3f}{r['control_overhead']:>8.0%}")
    print("bare s: the same number of bare p.stepSimulation calls on the same scene, robot at rest (median of 15)."
          "\nphysics s: time inside p.stepSimulation during our run (a moving, grasping robot costs more per step);"
          "\ncontrol: everything else (IK, timing, drives, checks) as a fraction of that physics time.")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"robot": robot, "task": args.task, "seed": args.seed, "rows": rows}, fh, indent=2)


if __name__ == "__main__":
    main()
