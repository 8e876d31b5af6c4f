"""A still PyBullet scene to take pictures of: a robot YAML alone (on the ground, base at the
origin) or a task YAML's whole world (table, pedestal, objects, obstacles, every robot).

Joints are *teleported* (no stepping): the arm at ``home`` or at the given ``q``, each parallel
gripper at ``open`` with its mimic followers where the URDF's ``<mimic>`` puts them. Frames:
world, z up, metres.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence

import numpy as np
import pybullet as p

from robocfg.checks.robot import CheckedRobot
from robocfg.checks.task import CheckedTask
from robocfg.config.robot import ParallelGripperConfig
from robocfg.errors import ConfigError, Problem
from robocfg.sim.bodies import spawn_ground
from robocfg.sim.loading import load_robot_urdf
from robocfg.sim.robot import RobotHandle
from robocfg.sim.world import World


class StillScene:
    """PyBullet DIRECT client holding the robots (``robots``) and, for a task, its ``world``.

    ``t`` is always 0 (a recorder taking one frame reads it). Use as a context manager.
    """

    def __init__(self, client: int, robots: list[RobotHandle], world: World | None = None,
                 scenery: Sequence[int] = ()):
        self.client, self.robots, self.world = client, robots, world
        self.scenery = list(scenery)  # body ids of non-robot bodies other than the ground
        self.t = 0.0

    @classmethod
    def of_robot(cls, robot: CheckedRobot, q: Sequence[float] | None = None) -> StillScene:
        """The robot alone, its URDF root at the origin, first arm at ``q`` (rad/m) or home."""
        client = p.connect(p.DIRECT)
        try:
            spawn_ground(client)
            body = load_robot_urdf(client, robot, (0, 0, 0), (0, 0, 0, 1), 0)
            scene = cls(client, [RobotHandle(client, body, robot)])
            scene.pose_arms(q)
            return scene
        except BaseException:
            p.disconnect(physicsClientId=client)
            raise

    @classmethod
    def of_task(cls, task: CheckedTask, q: Sequence[float] | None = None) -> StillScene:
        """The task's world as built for a run (robots at their mounts), first arm at ``q`` or home."""
        world = World(task)
        skip = {"ground", *(r.name for r in world.robots)}
        scenery = [bid for name, bid in world.bodies.items() if name not in skip]
        scene = cls(world.client, world.robots, world, scenery)
        try:
            scene.pose_arms(q)
        except BaseException:
            world.close()
            raise
        return scene

    def pose_arms(self, q: Sequence[float] | None) -> None:
        """Teleport every arm to home (the first arm to ``q`` if given) and open the grippers."""
        for r, robot in enumerate(self.robots):
            for k, arm in enumerate(robot.arms.values()):
                target = arm.home
                if q is not None and r == 0 and k == 0:
                    if len(q) != len(arm.joints):
                        raise ConfigError([Problem("<command line>", None, None, "--q",
                                                   f"arm {arm.config.name!r} has {len(arm.joints)} joints "
                                                   f"({', '.join(arm.joints)}), got {len(q)} values")])
                    target = np.asarray(q, float)
                robot.reset_joints(arm.joints, target, hold=False)
                self._open_gripper(robot, arm.config)

    @staticmethod
    def _open_gripper(robot: RobotHandle, arm) -> None:
        g = arm.gripper
        if not isinstance(g, ParallelGripperConfig):
            return
        checked = robot.checked
        leaders = checked.gripper_joints(arm)
        q = dict(zip(leaders, g.open, strict=True))
        for name in checked.mimic_followers(leaders):
            q[name] = checked.urdf.joint_value(checked.urdf.joints[name], q)
        names = [n for n in q if n in robot.joint_index]
        robot.reset_joints(names, [q[n] for n in names], hold=False)

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """World axis-aligned box (lo, hi) around the robots and the scenery (not the ground), m."""
        boxes = []
        for robot in self.robots:
            for li in robot.link_index.values():
                boxes.append(p.getAABB(robot.body_id, li, physicsClientId=self.client))
        for bid in self.scenery:
            for li in range(-1, p.getNumJoints(bid, physicsClientId=self.client)):
                boxes.append(p.getAABB(bid, li, physicsClientId=self.client))
        lo = np.min([b[0] for b in boxes], axis=0)
        hi = np.max([b[1] for b in boxes], axis=0)
        return lo, hi

    def robot_collision_aabbs(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """World axis-aligned box (lo, hi) of every robot link that has a collision shape, m."""
        out = []
        for robot in self.robots:
            for li in robot.link_index.values():
                if not p.getCollisionShapeData(robot.body_id, li, physicsClientId=self.client):
                    continue
                lo, hi = p.getAABB(robot.body_id, li, physicsClientId=self.client)
                out.append((np.asarray(lo, float), np.asarray(hi, float)))
        return out

    def close(self) -> None:
        if self.world is not None:
            self.world.close()
        elif self.client >= 0:
            with contextlib.suppress(p.error):
                p.disconnect(physicsClientId=self.client)
        self.client = -1

    def __enter__(self) -> StillScene:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
