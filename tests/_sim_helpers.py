"""Shared helpers for the simulation tests: write a task YAML around a robot and load it."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from robocfg.checks import load_task
from robocfg.engine.options import EpisodeObserver

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
SHIPPED_ROBOTS = sorted((ROOT / "robocfg" / "data" / "robots").glob("*.yaml"))
PANDA = ROOT / "robocfg" / "data" / "robots" / "panda.yaml"  # the reference robot of the generic tests


def make_task(tmp_path: Path, robot_file: Path | str, *, objects=(), mount=None, extra=None, task="gripper",
              name: str = "task.yaml"):
    """Write a minimal ``task: gripper`` YAML using ``robot_file`` (absolute path) and load it.

    A gripper task holds its first object (a suction gripper's test needs one to hold); with no
    objects and no ``gripper`` block it is a ``follow_target`` task, a world with just the robot
    (a gripper task with nothing to hold is invalid for a suction gripper)."""
    if task == "gripper" and not objects and "gripper" not in (extra or {}):
        task = "follow_target"
    data = {
        "schema_version": 1,
        "task": task,
        "robots": [{"robot_config_file": str(Path(robot_file).resolve()), **(mount or {})}],
        "scene": {"ground": True, "objects": list(objects)},
    }
    if task == "gripper" and objects:
        data["gripper"] = {"hold_object": objects[0]["name"]}
    for k, v in (extra or {}).items():
        data[k] = v
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)


class ContactSpy(EpisodeObserver):
    """Stands in for a Recorder: after every physics step, counts steps where a moving robot link
    or the cube penetrates the ``obstacle``."""

    def __init__(self, world, obstacle: str = "wall"):
        self.world, self.obstacle, self.checked, self.robot_hits, self.cube_hits = world, obstacle, 0, 0, 0

    def maybe_capture(self):
        import pybullet as p

        w, c = self.world, self.world.client
        wall = w.bodies[self.obstacle]
        robot = [k for k in p.getContactPoints(w.robot.body_id, wall, physicsClientId=c) if k[8] < 0 and k[3] != -1]
        cube = [k for k in p.getContactPoints(w.bodies["cube"], wall, physicsClientId=c) if k[8] < 0]
        self.robot_hits += bool(robot)
        self.cube_hits += bool(cube)
        self.checked += 1

    def save(self):
        pass


def run_spied(task, make_spy, seed: int = 0, episodes: int = 1):
    """Run pick-place with ``make_spy(world)`` recording episode 0; (report, that spy)."""
    from robocfg.runners.pick_place import run_pick_place

    spies = []

    def factory(world):
        spies.append(make_spy(world))
        return spies[-1]

    report, _ = run_pick_place(task, episodes=episodes, seed=seed, record=factory)
    return report, spies[0]


def panda_branch_case() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Panda's branch case: ``(T, T_down, q0)``. ``T`` is a top-down pre-grasp pose
    (world_T_ee, m) whose nearest IK answer from ``q0`` (rad) has the wrist past 2.9 rad;
    ``T_down`` is the same pose 13 cm lower. Going straight down from that answer, a joint jumps
    (a branch is crossed); other answers of ``T`` have a continuous line."""
    c, s = np.cos(-2.618), np.sin(-2.618)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]) @ np.diag([1.0, -1.0, -1.0]), [0.5, -0.3, 0.25]
    T_down = T.copy()
    T_down[2, 3] = 0.12
    return T, T_down, np.array([1.363, -1.189, 2.155, -1.441, -1.189, 1.565, -2.799])
