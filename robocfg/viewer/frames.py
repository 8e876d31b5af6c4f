"""The frames a robot YAML declares, as world-frame geometry any front-end can draw.

For each arm: triads (x red, y green, z blue) for the arm's ``base_link``, ``ee_link``, the TCP
and the GraspNet grasp frame (origin at the TCP, x = approach, y = closing, z = x × y, with
``world_R_grasp = world_R_ee · R_ee_graspnetᵀ``), an arrow from the ``ee_link`` origin along
``ee_axis`` to the TCP, and a box around each finger pad (gripper open). These are the numbers a
new robot YAML gets wrong (``tcp_offset``, ``ee_axis``, ``R_ee_graspnet``); drawing them on the
robot shows at once whether the TCP sits between the pads and the grasp x axis leaves the palm.

All poses are 4x4 homogeneous matrices, world frame, metres. numpy only: link poses come from a
callable, so PyBullet (pictures) and the URDF's own FK (browser viewer) feed the same code.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robocfg.assets.fingers import FingerGeometryMissing, finger_points, pad_points
from robocfg.assets.paths import Resolver
from robocfg.checks.robot import CheckedRobot
from robocfg.config.robot import ArmConfig, ParallelGripperConfig
from robocfg.config.types import AXIS_INDEX
from robocfg.kinematics.frames import tcp_from_ee

LinkPose = Callable[[str], np.ndarray]  # link name → 4x4 world pose of its URDF frame


@dataclass(frozen=True)
class Triad:
    """A labelled frame: ``pose`` (4x4 world), axes drawn ``length`` m long; ``axis_labels``
    names what x, y, z mean here (the grasp frame says approach/closing)."""

    label: str
    pose: np.ndarray
    length: float
    axis_labels: tuple[str, str, str] = ("x", "y", "z")


@dataclass(frozen=True)
class Arrow:
    """A labelled arrow from ``start`` to ``end`` (world, m)."""

    label: str
    start: np.ndarray
    end: np.ndarray


@dataclass(frozen=True)
class PadBox:
    """An oriented box around a finger pad: ``corners`` (8, 3) world m, in the order of
    :data:`BOX_EDGES`."""

    label: str
    corners: np.ndarray


# corner k has bits (x, y, z) = (k & 1, k >> 1 & 1, k >> 2 & 1): lo or hi on each axis
BOX_EDGES = ((0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7))


@dataclass(frozen=True)
class ArmFrames:
    """Everything drawn for one arm."""

    arm: str
    triads: tuple[Triad, ...]
    ee_axis: Arrow
    pads: tuple[PadBox, ...]

    def tcp(self) -> np.ndarray:
        """World position of the TCP (m)."""
        return self.ee_axis.end


def grasp_pose(T_tcp: np.ndarray, arm: ArmConfig) -> np.ndarray:
    """World pose of the GraspNet grasp frame at the TCP: ``world_R_grasp = world_R_ee · R_ee_graspnetᵀ``."""
    T = np.array(T_tcp, float)
    T[:3, :3] = T_tcp[:3, :3] @ np.asarray(arm.R_ee_graspnet, float).T
    return T


def pad_boxes_ee(robot: CheckedRobot, arm: ArmConfig) -> list[tuple[np.ndarray, np.ndarray]]:
    """(lo, hi) corners in the ``ee_link`` frame (m) of each finger pad with the gripper open;
    empty for suction cups and for fingers without geometry."""
    g = arm.gripper
    if not isinstance(g, ParallelGripperConfig):
        return []
    resolver = Resolver(robot.path.parent, robot.config.package_dirs)
    try:
        points = finger_points(robot.urdf, resolver, list(g.finger_links))
    except FingerGeometryMissing:
        return []
    q_open = dict(zip(robot.gripper_joints(arm), g.open, strict=True))
    pads = pad_points(robot.urdf, arm.ee_link, list(g.finger_links), points, q_open, AXIS_INDEX[arm.ee_axis])
    return [(P.min(axis=0), P.max(axis=0)) for P in pads]


def box_corners(lo: np.ndarray, hi: np.ndarray, T: np.ndarray) -> np.ndarray:
    """(8, 3) corners of the box [lo, hi] (given in the frame ``T``) in the world."""
    c = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] for k in range(8)])
    return c @ T[:3, :3].T + T[:3, 3]


def arm_frames(arm: ArmConfig, link_pose: LinkPose, pads_ee: list[tuple[np.ndarray, np.ndarray]],
               length: float) -> ArmFrames:
    """The triads, ``ee_axis`` arrow and pad boxes of ``arm`` at the current link poses;
    triad axes ``length`` m long (the grasp triad a little longer so it stands out)."""
    T_base, T_ee = link_pose(arm.base_link), link_pose(arm.ee_link)
    T_tcp = tcp_from_ee(T_ee, arm)
    prefix = f"{arm.name}: " if arm.name != "arm" else ""
    triads = (
        Triad(f"{prefix}base ({arm.base_link})", T_base, length * 1.5),
        Triad(f"{prefix}ee_link ({arm.ee_link})", T_ee, length),
        Triad(f"{prefix}TCP", T_tcp, length * 0.6),
        Triad(f"{prefix}grasp", grasp_pose(T_tcp, arm), length * 1.2, ("approach", "closing", "z")),
    )
    arrow = Arrow(f"{prefix}ee_axis +{arm.ee_axis}", T_ee[:3, 3].copy(), T_tcp[:3, 3].copy())
    pads = tuple(PadBox(f"{prefix}pad {k}", box_corners(lo, hi, T_ee)) for k, (lo, hi) in enumerate(pads_ee))
    return ArmFrames(arm.name, triads, arrow, pads)
