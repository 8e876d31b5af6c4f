"""Global planner benchmark: random start/goal pairs in a shelf scene, planner vs reactive controller.

    python benchmarks/bench_planner.py [--pairs 100] [--seed 0] [--robots panda,ur5e_robotiq_2f85] [--json out.json] [--no-reactive]

The scene: the ground and an open shelf in front of the robot (back panel, two sides, four boards:
three compartments). Each query's start and goal are arm configurations with the TCP at a random
point either inside a shelf compartment (tool pointing into the shelf) or above the floor beside
the shelf (tool pointing down): IK from home, or from seeded random restarts, kept only if
collision-free with a 1 cm margin; the goal's IK is seeded from the start, as a planned move in
pick-place seeds it from the current joints. The same pairs go to

* the planner (:class:`robocfg.planning.JointPlanner`: straight segment or OMPL RRT-Connect, then
  shortening; toppra timing checked sample by sample): success, planning time (search +
  shortening, and toppra timing), collision checks, joint-path length (rad); then the timed
  trajectory is executed in PyBullet (position drives) and every physics step's robot–shelf
  contacts are counted;
* the reactive controller alone (the follow-target controller, as ``motion: reactive`` drives
  pick-place), sent to the goal's EE pose from the same start: success (within 5 mm / 0.05 rad in
  10 s simulated), robot–shelf contact steps.

Goals (issue 18): ≥ 99 % planned, median planning time ≤ 50 ms, 0 contacts in execution.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from robocfg.checks import load_task
from robocfg.config import catalog

FRONT, DEPTH, WIDTH, HEIGHT, BOARD = 0.55, 0.30, 0.80, 0.90, 0.02  # m: shelf front face x, sizes
LEVELS = [0.0, 0.30, 0.60, HEIGHT]  # board tops (m); compartments between consecutive boards
R_INTO_SHELF = Rotation.from_euler("y", 90, degrees=True).as_matrix()  # tool z along +x
R_DOWN = np.diag([1.0, -1.0, -1.0])
REACTIVE_TIMEOUT = 10.0  # s simulated per reactive query


def shelf_bodies() -> list[dict]:
    """The shelf as static boxes (task YAML ``scene.obstacles``)."""
    cx = FRONT + DEPTH / 2
    grey = [0.6, 0.55, 0.5, 1.0]
    out = [
        {"name": "shelf_back", "shape": "box", "size": [BOARD, WIDTH, HEIGHT], "position": [FRONT + DEPTH, 0, HEIGHT / 2]},
        {"name": "shelf_left", "shape": "box", "size": [DEPTH, BOARD, HEIGHT], "position": [cx, WIDTH / 2, HEIGHT / 2]},
        {"name": "shelf_right", "shape": "box", "size": [DEPTH, BOARD, HEIGHT], "position": [cx, -WIDTH / 2, HEIGHT / 2]},
    ]
    for k, z in enumerate(LEVELS):
        zc = max(z - BOARD / 2, BOARD / 2)
        out.append({"name": f"shelf_board_{k}", "shape": "box", "size": [DEPTH, WIDTH, BOARD], "position": [cx, 0, zc]})
    for b in out:
        b.update(euler_deg=[0, 0, 0], color=grey, mass=0.0)
    return out


def shelf_task(robot: str, folder: Path):
    data = {"schema_version": 1, "task": "gripper", "robots": [{"robot": robot}],
            "scene": {"ground": True, "obstacles": shelf_bodies()}}
    path = folder / f"shelf_{robot}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)


def random_pose(rng: np.random.Generator) -> np.ndarray:
    """A TCP pose inside a shelf compartment (pointing in) or beside the shelf (pointing down)."""
    T = np.eye(4)
    if rng.uniform() < 0.6:
        k = int(rng.integers(0, 2))  # the two lower compartments (the top one is out of reach)
        T[:3, :3] = R_INTO_SHELF
        T[:3, 3] = [FRONT + rng.uniform(0.04, 0.12), rng.uniform(-0.25, 0.25), LEVELS[k] + rng.uniform(0.10, 0.18)]
    else:
        T[:3, :3] = R_DOWN
        T[:3, 3] = [rng.uniform(0.2, 0.45), rng.choice([-1.0, 1.0]) * rng.uniform(0.35, 0.55), rng.uniform(0.10, 0.35)]
    return T


def free_ik(kin, checker, T_tcp, rng, near=None, restarts: int = 6):
    """A collision-free IK answer for the TCP pose (seeded from ``near``, then home, then random), or None."""
    first = [kin.home] if near is None else [near, kin.home]
    seeds = [*first, *(rng.uniform(kin.lower, kin.upper) for _ in range(restarts))]
    for seed in seeds:
        res = kin.ik(T_tcp, seed_q=seed, time_budget=0.05, rng=rng)
        if res.converged and checker.is_valid(res.q):
            return res.q
    return None


def sample_pairs(kin, checker, n: int, seed: int) -> tuple[list[tuple[np.ndarray, np.ndarray]], int]:
    """``n`` (start, goal) pairs and how many random poses had no collision-free IK answer."""
    rng = np.random.default_rng(seed)
    pairs, rejected = [], 0
    while len(pairs) < n:
        q_start = free_ik(kin, checker, random_pose(rng), rng)
        if q_start is None:
            rejected += 1
            continue
        q_goal = free_ik(kin, checker, random_pose(rng), rng, near=q_start)  # as a planned move picks it
        if q_goal is None:
            rejected += 1
        elif np.max(np.abs(q_goal - q_start)) > 0.05:
            pairs.append((q_start, q_goal))
    return pairs, rejected


class ContactCounter:
    """Counts physics steps where a moving robot link penetrates a shelf part."""

    def __init__(self, world):
        self.world = world
        self.shelf = {world.bodies[b["name"]] for b in shelf_bodies()}
        self.steps = 0
        self.deepest = 0.0

    def __call__(self) -> None:
        import pybullet as p

        w = self.world
        hits = [k for k in p.getContactPoints(w.robot.body_id, physicsClientId=w.client)
                if k[2] in self.shelf and k[8] < 0 and k[3] != -1]
        if hits:
            self.steps += 1
            self.deepest = min(self.deepest, min(k[8] for k in hits))


def run_robot(robot: str, pairs_n: int, seed: int, reactive: bool, folder: Path) -> dict:
    from robocfg.config.commands import Limits
    from robocfg.errors import PhaseFailed
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.limits import limits_from_robot
    from robocfg.motion.moves import ArmMover, bound_ik_by_iterations
    from robocfg.motion.plan import load_libraries
    from robocfg.planning import PlanningFailed
    from robocfg.planning.drive import build_planned_drive
    from robocfg.sim.world import World

    task = shelf_task(robot, folder)
    checked = task.robots[0]
    load_libraries()
    with World(task) as world:
        arm = world.robot.arm()
        kin = KinematicModel.from_robot(checked, base_pose=world.robot.base_pose())
        bound_ik_by_iterations(kin)
        limits = limits_from_robot(checked, arm.joints, Limits())
        drive = build_planned_drive(checked, world, kin)
        planner, checker = drive.planner, drive.checker
        pairs, rejected = sample_pairs(kin, checker, pairs_n, seed)
        counter = ContactCounter(world)
        mover = ArmMover(world, arm, kin, limits, on_step=counter, timeout=REACTIVE_TIMEOUT, phase="move")
        reactive_drive = None
        if reactive:
            from robocfg.motion.reactive_drive import build_reactive_drive

            reactive_drive = build_reactive_drive(checked, world, arm.config.name)
        rows = []
        for i, (qs, qg) in enumerate(pairs):
            row: dict = {"index": i}
            # -- planner ------------------------------------------------------------------------
            try:
                path = planner.plan(qs, qg)
                t0 = time.perf_counter()
                plan = planner.timed(path, limits)
                row.update(planned=True, plan_ms=path.seconds * 1e3, plan_cpu_ms=path.cpu_seconds * 1e3, timing_ms=(time.perf_counter() - t0) * 1e3,
                           checks=path.checks, method=path.method, length_rad=path.length,
                           raw_length_rad=path.raw_length, waypoints=len(path.waypoints), duration_s=plan.duration,
                           timing=plan.method)
                _reset(world, arm, qs)
                counter.steps, counter.deepest = 0, 0.0
                mover.play(plan.trajectory)
                try:
                    mover.converge(kin.fk(qg, "ee"), world.t - plan.duration)
                    row["executed"] = True
                except PhaseFailed:
                    row["executed"] = False
                row.update(contact_steps=counter.steps, deepest_mm=-counter.deepest * 1e3)
            except PlanningFailed as exc:
                row.update(planned=False, reason=exc.reason)
            # -- reactive controller alone ------------------------------------------------------
            if reactive_drive is not None:
                _reset(world, arm, qs)
                counter.steps, counter.deepest = 0, 0.0
                t_sim = world.t
                try:
                    mover.move_reactive(kin.fk(qg, "ee"), reactive_drive)
                    ok = True
                except PhaseFailed:
                    ok = False
                row.update(reactive_ok=ok, reactive_contact_steps=counter.steps,
                           reactive_deepest_mm=-counter.deepest * 1e3, reactive_sim_s=world.t - t_sim)
            rows.append(row)
    return {"robot": robot, "pairs": len(rows), "ik_rejected_poses": rejected, "rows": rows,
            "summary": summarise(rows, reactive)}


def _reset(world, arm, q) -> None:
    world.robot.reset_joints(arm.joints, q)
    arm.command(q, np.zeros_like(q))
    world.step(1)


def summarise(rows: list[dict], reactive: bool) -> dict:
    ok = [r for r in rows if r["planned"]]
    plan = np.array([r["plan_ms"] for r in ok]) if ok else np.array([np.nan])
    cpu = np.array([r["plan_cpu_ms"] for r in ok]) if ok else np.array([np.nan])
    total = np.array([r["plan_ms"] + r["timing_ms"] for r in ok]) if ok else np.array([np.nan])
    out = {
        "planned_pct": 100.0 * len(ok) / len(rows),
        "plan_ms_median": float(np.median(plan)), "plan_ms_p95": float(np.percentile(plan, 95)),
        "plan_cpu_ms_median": float(np.median(cpu)), "plan_cpu_ms_p95": float(np.percentile(cpu, 95)),
        "plan_and_timing_ms_median": float(np.median(total)), "plan_and_timing_ms_p95": float(np.percentile(total, 95)),
        "checks_median": float(np.median([r["checks"] for r in ok])) if ok else None,
        "direct_pct": 100.0 * sum(r["method"] == "direct" for r in ok) / max(1, len(ok)),
        "length_rad_median": float(np.median([r["length_rad"] for r in ok])) if ok else None,
        "length_rad_p95": float(np.percentile([r["length_rad"] for r in ok], 95)) if ok else None,
        "raw_length_rad_median": float(np.median([r["raw_length_rad"] for r in ok])) if ok else None,
        "executed_pct": 100.0 * sum(r.get("executed", False) for r in ok) / max(1, len(ok)),
        "contact_queries": sum(r.get("contact_steps", 0) > 0 for r in ok),
        "contact_steps": sum(r.get("contact_steps", 0) for r in ok),
    }
    if reactive:
        out.update(
            reactive_pct=100.0 * sum(r["reactive_ok"] for r in rows) / len(rows),
            reactive_contact_queries=sum(r["reactive_contact_steps"] > 0 for r in rows),
            reactive_contact_steps=sum(r["reactive_contact_steps"] for r in rows),
            reactive_deepest_mm=max(r["reactive_deepest_mm"] for r in rows),
        )
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robots", default="panda,ur5e_robotiq_2f85")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--no-reactive", action="store_true")
    a = ap.parse_args()
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        for robot in a.robots.split(","):
            catalog.find("robots", robot)  # a clear error for an unknown robot name
            res = run_robot(robot, a.pairs, a.seed, not a.no_reactive, Path(tmp))
            results.append(res)
            s = res["summary"]
            print(f"\n{robot}: {res['pairs']} pairs (poses without a collision-free IK answer: {res['ik_rejected_poses']})")
            for k, v in s.items():
                print(f"  {k:28s} {v:.1f}" if isinstance(v, float) else f"  {k:28s} {v}")
    if a.json:
        a.json.write_text(json.dumps(results, indent=1))
    ok = all(r["summary"]["planned_pct"] >= 99 and r["summary"]["plan_cpu_ms_median"] <= 50
             and r["summary"]["contact_steps"] == 0 for r in results)
    print("\ngoals (>= 99 % planned, median planning CPU time <= 50 ms, 0 contact steps):", "met" if ok else "NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
