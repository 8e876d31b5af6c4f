"""The pick-place obstacle task in its three free-space modes, side by side in one process:
``trajectory`` (IK + min-jerk, blind to the wall), ``planned`` (global planner) and ``reactive``
(follow-target controller), and ``trajectory`` on the same task with the wall taken out (the
same work with nothing in the way: the yardstick).

    python benchmarks/bench_obstacle_modes.py [--episodes 20] [--seed 0] [--rounds 2] [--json out.json]

Per mode: success, simulated time per episode, wall and CPU time per episode (the whole run,
world build and one-off imports included, divided by the episodes; and the episodes alone; and
of those, the wall time inside PyBullet's ``stepSimulation``),
physics steps with a robot link or the cube inside the wall. The modes run in turns (``--rounds``
times each, in rotated order) so that a load change on the machine hits them alike; the figure
per mode is the median over its rounds. Goal (issue 18): planned wall time ≤ 1.3 × the
trajectory mode's (with the wall in place the trajectory mode runs into it and times out).
A first throw-away run loads the libraries every mode shares (pinocchio, PyBullet, toppra...).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.runners.pick_place import run_pick_place

MODES = ("trajectory", "planned", "reactive", "trajectory_no_wall")


class WallContacts:
    """A dataset-sink stand-in: counts physics steps with a robot link or the cube inside the wall."""

    def __init__(self):
        self.robot_steps = self.cube_steps = self.steps = 0

    def begin(self, world, arm, obj, phase_of, phases=(), language=""):
        return _Episode(self, world, obj)

    def end(self, rec, index, seed, success, failed_phase, reason):
        pass


class _Episode:
    """The sink's tap (``robocfg.engine.dataset.EpisodeTap``): hooked into the world's physics
    steps from ``begin`` until ``stop``; it sends no commands, so nothing reaches the drives late."""

    lag_steps = 0

    def __init__(self, total: WallContacts, world, obj: int):
        self.total, self.world, self.obj = total, world, obj
        self.wall = world.bodies.get("wall")
        world.step_hooks.append(self.on_step)

    def stop(self) -> None:
        if self.on_step in self.world.step_hooks:
            self.world.step_hooks.remove(self.on_step)

    def on_step(self) -> None:
        import pybullet as p

        if self.wall is None:
            return
        w, c, t = self.world, self.world.client, self.total
        robot = [k for k in p.getContactPoints(w.robot.body_id, self.wall, physicsClientId=c) if k[8] < 0 and k[3] != -1]
        cube = [k for k in p.getContactPoints(self.obj, self.wall, physicsClientId=c) if k[8] < 0]
        t.robot_steps += bool(robot)
        t.cube_steps += bool(cube)
        t.steps += 1


def run_mode(task, mode: str, episodes: int, seed: int) -> dict:
    """``trajectory_no_wall``: the trajectory mode on the same task with the wall taken out (the
    same pick-place work with nothing in the way: the yardstick the goal compares with)."""
    motion = mode.removesuffix("_no_wall")
    params = task.config.pick_place.model_copy(update={"motion": motion})
    config = task.config.model_copy(update={"pick_place": params})
    if mode.endswith("_no_wall"):
        config = config.model_copy(update={"scene": config.scene.model_copy(update={"obstacles": []})})
    t = replace(task, config=config)
    contacts = WallContacts()
    w0, c0 = time.perf_counter(), time.process_time()
    report, timing = run_pick_place(t, episodes=episodes, seed=seed, sink=contacts)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    eps = report.episodes
    return {"mode": mode, "success": sum(e.success for e in eps), "episodes": len(eps),
            "failures": sorted({f"{e.failed_phase}: {e.reason}" for e in eps if not e.success}),
            "sim_s_per_episode": float(np.mean([e.sim_time for e in eps])),
            "wall_s_per_episode": wall / episodes, "cpu_s_per_episode": cpu / episodes,
            "episode_wall_s": timing.mean_episode, "physics_wall_s": timing.mean_physics,
            "robot_wall_contact_steps": contacts.robot_steps, "cube_wall_contact_steps": contacts.cube_steps}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--modes", default=",".join(MODES), help="comma-separated subset (the ratio needs planned and trajectory_no_wall)")
    a = ap.parse_args()
    modes = tuple(m for m in MODES if m in a.modes.split(","))
    task = load_task(catalog.find("tasks", "pick_place_obstacle"))
    for mode in modes:  # throw-away: one-off imports and caches out of the figures
        run_mode(task, mode, 1, a.seed)
    runs: dict[str, list[dict]] = {m: [] for m in modes}
    for r in range(a.rounds):
        for mode in modes[r % len(modes):] + modes[: r % len(modes)]:
            runs[mode].append(run_mode(task, mode, a.episodes, a.seed))
    keys = ["wall_s_per_episode", "cpu_s_per_episode", "episode_wall_s", "physics_wall_s", "sim_s_per_episode"]
    table = {m: {**runs[m][0], **{k: float(np.median([x[k] for x in runs[m]])) for k in keys}} for m in modes}
    print(f"pick_place_obstacle, {a.episodes} episodes × {a.rounds} rounds per mode (median of rounds)")
    print(f"{'mode':19s} {'success':>8s} {'sim s/ep':>9s} {'wall s/ep':>10s} {'cpu s/ep':>9s} {'episode wall s':>15s} "
          f"{'physics s':>10s} {'robot–wall steps':>17s} {'cube–wall steps':>16s}")
    for m in modes:
        x = table[m]
        print(f"{m:19s} {x['success']:>4d}/{x['episodes']:<3d} {x['sim_s_per_episode']:9.2f} {x['wall_s_per_episode']:10.3f} "
              f"{x['cpu_s_per_episode']:9.3f} {x['episode_wall_s']:15.3f} {x['physics_wall_s']:10.3f} {x['robot_wall_contact_steps']:17d} "
              f"{x['cube_wall_contact_steps']:16d}")
    base = table["trajectory_no_wall"]
    ratio = {k: table["planned"][k] / base[k] for k in ("wall_s_per_episode", "cpu_s_per_episode")}
    print(f"planned / trajectory without the wall: wall {ratio['wall_s_per_episode']:.2f}×, CPU {ratio['cpu_s_per_episode']:.2f}×; "
          + (f"reactive / trajectory without the wall: wall {table['reactive']['wall_s_per_episode'] / base['wall_s_per_episode']:.2f}×, "
             f"CPU {table['reactive']['cpu_s_per_episode'] / base['cpu_s_per_episode']:.2f}×" if "reactive" in table else ""))
    if a.json:
        a.json.write_text(json.dumps({"table": table, "runs": runs, "ratio": ratio}, indent=1))
    ok = ratio["wall_s_per_episode"] <= 1.3 and table["planned"]["robot_wall_contact_steps"] == 0 \
        and table["planned"]["success"] == table["planned"]["episodes"]
    print("goal (planned wall ≤ 1.3 × trajectory without the wall, every episode placed, 0 robot–wall steps):", "met" if ok else "NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
