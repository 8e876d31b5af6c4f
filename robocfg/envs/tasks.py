"""The four environments: Reach, Push, PickPlace, FollowTarget (``RobotEnv`` subclasses).

Reach: bring the TCP to a goal point. Push: push a 5 cm cube to a goal on the ground with the
gripper closed. PickPlace: carry the cube to a goal on the ground or up to 20 cm above it.
FollowTarget: keep the TCP on a target moving along a horizontal circle (never terminates).
Goals are sampled with the episode's seeded generator (``self.np_random``).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from robocfg.envs.core import RobotEnv


class _ObjectEnv(RobotEnv):
    """A task about the cube: the achieved goal is the cube's position."""

    uses_object = True

    def _place_scene(self) -> None:
        rng, ws = self.np_random, self.workspace
        xy = ws.sample_xy(rng)
        self.world.set_body_pose(self.object, [xy[0], xy[1], ws.floor + self.object_half_height])

    def _achieved(self) -> np.ndarray:
        return self.world.body_pose(self.object)[0]

    def _task_observation(self) -> np.ndarray:
        """Cube position (m), orientation (xyz Euler, rad), linear (m/s) and angular (rad/s) velocity."""
        pos, quat = self.world.body_pose(self.object)
        lin, ang = self.world.body_velocity(self.object)
        return np.concatenate([pos, Rotation.from_quat(quat).as_euler("xyz"), lin, ang])

    def _ground_goal(self, min_distance: float = 0.1) -> np.ndarray:
        rng, obj = self.np_random, self._achieved()
        for _ in range(100):
            xy = self.workspace.sample_xy(rng)
            if np.linalg.norm(xy - obj[:2]) >= min_distance:
                break
        return np.array([xy[0], xy[1], self.workspace.floor + self.object_half_height])


class ReachEnv(RobotEnv):
    """TCP to a goal point within the workspace (5–30 cm above its floor: the ground, or the stand)."""

    def _sample_goal(self) -> np.ndarray:
        xy = self.workspace.sample_xy(self.np_random)
        return np.array([xy[0], xy[1], self.workspace.floor + self.np_random.uniform(0.05, 0.3)])


class PushEnv(_ObjectEnv):
    """Push the cube to a goal on the ground; the gripper stays closed (no gripper action)."""

    def _place_scene(self) -> None:
        super()._place_scene()
        self._command_gripper(-1.0)

    def _sample_goal(self) -> np.ndarray:
        return self._ground_goal()


class PickPlaceEnv(_ObjectEnv):
    """Pick the cube and place it at a goal: on the ground (30 %) or up to 20 cm in the air."""

    uses_gripper = True

    def _sample_goal(self) -> np.ndarray:
        goal = self._ground_goal()
        if self.np_random.uniform() >= 0.3:
            goal[2] += self.np_random.uniform(0.0, 0.2)
        return goal

    def expert_action(self) -> np.ndarray:
        """The scripted pick-and-place policy's action for the current state (see ``expert.py``)."""
        from robocfg.envs.expert import pick_place_action

        return pick_place_action(self)


class FollowTargetEnv(RobotEnv):
    """Track a target moving on a horizontal circle (radius 8 cm, one turn in 8 s) whose centre
    and phase are random; success = within ``distance_threshold``; episodes only truncate."""

    RADIUS, PERIOD = 0.08, 8.0  # m, s

    def _sample_goal(self) -> np.ndarray:
        rng = self.np_random
        xy = self.workspace.sample_xy(rng) * 0.5 + self.workspace.center[:2] * 0.5
        self._circle = (np.array([xy[0], xy[1], self.workspace.floor + rng.uniform(0.15, 0.3)]), rng.uniform(0, 2 * np.pi))
        return self._on_circle(0.0)

    def _on_circle(self, t: float) -> np.ndarray:
        c, phase = self._circle
        a = phase + 2 * np.pi * t / self.PERIOD
        return c + self.RADIUS * np.array([np.cos(a), np.sin(a), 0.0])

    def _advance_goal(self) -> None:
        self.goal = self._on_circle(self.steps * self.step_time)

    def _terminate_on_success(self) -> bool:
        return False
