"""A scripted pick-and-place expert for ``PickPlaceEnv``, for imitation learning and as a check
that the environment can be solved through its own action interface.

It reads the simulator state (TCP, cube, gripper contacts) and returns an ordinary action:
move above the cube, descend with the gripper open until the TCP is at the cube's centre, close
until both fingers hold it, lift, carry above the goal, lower onto it. Any phase goes back to
the start if the cube is lost. Pure feedback, no memory besides the "closing" counter, so it can
take over in the middle of an episode.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robocfg.sim.gripper import ParallelGripper

if TYPE_CHECKING:
    from robocfg.envs.tasks import PickPlaceEnv

ABOVE = 0.08  # m: approach and carry height above the cube / goal
XY_TOL = 0.01  # m: horizontal error before descending
Z_TOL = 0.01  # m: vertical error before closing


def _towards(env: PickPlaceEnv, target: np.ndarray) -> np.ndarray:
    return np.clip((target - env.tcp()) / env.ee_step, -1.0, 1.0)


def pick_place_action(env: PickPlaceEnv) -> np.ndarray:
    """One action ``[dx, dy, dz, grip]`` (``control="ee"`` only)."""
    if env.control != "ee":
        raise ValueError("the expert drives the end effector: make the env with control='ee'")
    tcp, goal = env.tcp(), env.goal
    cube = env.world.body_pose(env.object)[0]
    # grasp point: the cube's centre between fingers; its top face for a suction cup
    fingers = isinstance(env.gripper, ParallelGripper)
    grasp = cube + (0.0 if fingers else env.object_half_height) * np.array([0, 0, 1.0])
    held = env.gripper is not None and env.gripper.is_grasping(env.object) and np.linalg.norm(grasp - tcp) < 0.05
    if held:
        flat = np.linalg.norm(goal[:2] - cube[:2])
        above_goal = np.array([goal[0], goal[1], max(goal[2], cube[2], tcp[2] if flat > XY_TOL * 2 else 0)])
        if flat > XY_TOL * 2:
            target = tcp + (above_goal - cube)
            target[2] = max(target[2], goal[2] + ABOVE * 0.5 + (tcp[2] - cube[2]))
        else:
            target = tcp + (goal - cube)
        return np.append(_towards(env, target), -1.0)
    gap_xy = np.linalg.norm(cube[:2] - tcp[:2])
    if gap_xy > XY_TOL and tcp[2] < cube[2] + ABOVE * 0.5:
        # beside the cube and low: rise first, opening, so the fingers do not sweep it away
        return np.append(_towards(env, np.array([tcp[0], tcp[1], cube[2] + ABOVE])), 1.0)
    if gap_xy > XY_TOL:
        return np.append(_towards(env, np.array([cube[0], cube[1], cube[2] + ABOVE])), 1.0)
    if abs(tcp[2] - grasp[2]) > Z_TOL and env.gripper_opening() > 0.9:
        return np.append(_towards(env, grasp), 1.0)
    return np.append(_towards(env, grasp), -1.0)  # at the cube: close (hold position meanwhile)
