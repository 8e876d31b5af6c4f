"""A task's orientation on the robot that runs it: the tool frame converted to ``ee_link``, and the
half turn a symmetric gripper does not see.

Task orientations (follow-target's ``target_euler_deg``, the trajectory's Cartesian waypoints) are
written in ``orientation_frame``: ``tool`` (default; z = approach, y = closing axis, through the
robot's ``R_ee_graspnet``, see :mod:`robocfg.kinematics.frames`) or ``ee_link``. The controller
and IK work on the TCP frame, which has ``ee_link``'s rotation: :func:`ee_target_rotation`.

Tool roll (follow-target's ``tool_roll``): a parallel gripper's two jaws close symmetrically, so
the gripper turned half a turn about its axis is the same tool pose; a task written for another
robot may ask for the turn its home does not have (the drafted UR10 + 2F-85 started half a turn
from the target: 1.6 s of wrist turn at the 2 rad/s cap, "not reached"). ``symmetric`` keeps the
one of the two that is nearer the arm's home orientation; ``free`` (suction) leaves the roll to the
controller; ``tracked`` follows the target as written. Frames: world; rotations 3×3.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Literal

import numpy as np

from robocfg.config.robot import (
    ArmConfig,
    OneJawGripperConfig,
    ParallelGripperConfig,
    SuctionGripperConfig,
)
from robocfg.geometry import pose_matrix, rotation_angle
from robocfg.kinematics.frames import ee_rotation, half_turn

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask

ToolRoll = Literal["tracked", "symmetric", "free"]
CLEARLY_NEARER = math.radians(10.0)  # rad by which the half-turned target must be nearer the start to be taken


def resolved_tool_roll(setting: str, arm: ArmConfig) -> ToolRoll:
    """``tool_roll`` with ``auto`` decided by the gripper: free for suction, symmetric for a
    parallel gripper (two jaws), tracked for a one-jaw gripper or none."""
    if setting != "auto":
        return setting  # type: ignore[return-value]
    g = arm.gripper
    if isinstance(g, SuctionGripperConfig):
        return "free"
    if isinstance(g, ParallelGripperConfig) and not isinstance(g, OneJawGripperConfig):
        return "symmetric"
    return "tracked"


def home_rotation(task: CheckedTask, arm: str | None) -> np.ndarray:
    """world_R_tcp (3×3) of the task's first robot's ``arm`` at its home pose, as mounted."""
    from robocfg.kinematics.model import KinematicModel

    robot = task.robots[0]
    arm_cfg = robot.config.arm(arm)
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=pose_matrix(task.config.robots[0]))
    return model.fk(np.asarray(arm_cfg.home, float), "tcp")[:3, :3].copy()


def ee_target_rotation(R: np.ndarray, arm: ArmConfig, frame: str, roll: ToolRoll = "tracked",
                       start: np.ndarray | None = None) -> tuple[np.ndarray, bool]:
    """(world_R_ee for the task rotation ``R`` written in ``frame``, whether it was turned half a
    turn). With ``roll == "symmetric"`` and the arm's start rotation ``start``, the half-turned
    rotation is taken when it is nearer ``start`` by more than ``CLEARLY_NEARER`` (a target about a
    quarter turn from the start either way is kept as written: a near tie must not flip on rounding)."""
    R_ee = ee_rotation(R, arm, frame)
    if roll != "symmetric" or start is None:
        return R_ee, False
    turned = half_turn(R_ee, arm)
    if rotation_angle(start, turned) + CLEARLY_NEARER < rotation_angle(start, R_ee):
        return turned, True
    return R_ee, False
