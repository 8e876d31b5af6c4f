"""Grasp frames and the one conversion every grasping command uses (no per-robot constants).

GraspNet grasp frame: origin at the grasp centre between the fingers, x = approach direction
(gripper → object), y = finger closing direction, z = x × y. ``R_ee_graspnet`` is constant with
``world_R_ee = world_R_grasp · R_ee_graspnet``; the EE origin sits ``tcp_offset`` behind the TCP
along the EE's ``ee_axis``. All poses are 4x4 homogeneous matrices in the world frame (m).

Tool frame (what task orientations mean, ``orientation_frame: tool``): origin at the TCP, z = the
approach direction (grasp x), y = the closing direction (grasp y), x = y × z (= −grasp z). It is
defined through ``R_ee_graspnet``, so one task orientation is one physical tool pose on every
robot: ``[180, 0, 0]`` points the tool straight down with the fingers closing along world ∓y, on
a Panda (whose hand frame *is* its tool frame), a UR with tool0 turned a quarter turn from that,
or a Unitree Z1 whose approach axis is its ee_link's x.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robocfg.config.robot import ArmConfig, OneJawGripperConfig
from robocfg.config.types import AXIS_INDEX


@dataclass(frozen=True)
class Grasp:
    """A grasp: ``center`` (m, world), ``rotation`` world_R_grasp (3x3), ``width`` finger gap (m)."""

    center: np.ndarray
    rotation: np.ndarray
    width: float

    def approach(self) -> np.ndarray:
        return self.rotation[:, 0]

    def closing(self) -> np.ndarray:
        return self.rotation[:, 1]


def grasp_rotation(approach: np.ndarray, closing: np.ndarray) -> np.ndarray:
    """world_R_grasp from an approach and a closing direction (closing is orthogonalised).

    Two 3-vectors are done in Python floats with numpy's bits: each quotient, product and
    difference the one the elementwise arrays make, and numpy's 3-term dot products and norms
    sum their products left to right from 0.0 (tests/test_frames.py compares them on random
    vectors); a zero approach (numpy: NaN, not an error) and other shapes go the arrays' way."""
    a, c = np.asarray(approach, float), np.asarray(closing, float)
    if a.shape == (3,) and c.shape == (3,):
        (a0, a1, a2), (c0, c1, c2) = a.tolist(), c.tolist()
        na = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        if na != 0.0:
            x0, x1, x2 = a0 / na, a1 / na, a2 / na
            d = 0.0 + c0 * x0 + c1 * x1 + c2 * x2  # from 0.0, as numpy's dot: -0.0 products sum to +0.0
            y0, y1, y2 = c0 - d * x0, c1 - d * x1, c2 - d * x2
            n = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
            if n < 1e-9:
                raise ValueError("closing direction is parallel to the approach direction")
            y0, y1, y2 = y0 / n, y1 / n, y2 / n
            return np.array([[x0, y0, x1 * y2 - x2 * y1], [x1, y1, x2 * y0 - x0 * y2], [x2, y2, x0 * y1 - x1 * y0]])
    return _grasp_rotation_arrays(approach, closing)


def _grasp_rotation_arrays(approach: np.ndarray, closing: np.ndarray) -> np.ndarray:
    """:func:`grasp_rotation` with numpy arrays (any shape numpy takes; a zero approach gives NaN)."""
    x = np.asarray(approach, float) / np.linalg.norm(approach)
    y = np.asarray(closing, float) - np.dot(closing, x) * x
    n = np.linalg.norm(y)
    if n < 1e-9:
        raise ValueError("closing direction is parallel to the approach direction")
    y /= n
    (x0, x1, x2), (y0, y1, y2) = x.tolist(), y.tolist()
    z = [x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0]  # x × y, np.cross's arithmetic without its overhead
    return np.column_stack([x, y, z])


# grasp_R_tool: the tool frame's axes in grasp coordinates (x = −grasp z, y = grasp y, z = grasp x)
GRASP_R_TOOL = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])


def tool_R_ee(arm: ArmConfig) -> np.ndarray:
    """The rotation of ``ee_link`` in the tool frame (3x3): ``world_R_ee = world_R_tool · tool_R_ee``.
    The identity for an arm whose ``R_ee_graspnet`` is the Panda's (approach = ee z, closing = ee y)."""
    return GRASP_R_TOOL.T @ np.asarray(arm.R_ee_graspnet, float)


def ee_rotation(R: np.ndarray, arm: ArmConfig, frame: str) -> np.ndarray:
    """world_R_ee for a task orientation ``R`` (3x3, world) written in ``frame``: ``tool`` (the tool
    frame, converted through the robot's ``R_ee_graspnet``) or ``ee_link`` (already the ee_link's)."""
    R = np.asarray(R, float)
    T = tool_R_ee(arm)
    return R @ T if frame == "tool" and not np.array_equal(T, np.eye(3)) else R.copy()


def half_turn(R_ee: np.ndarray, arm: ArmConfig) -> np.ndarray:
    """``R_ee`` (world_R_ee) turned half a turn about the tool's axis (the arm's ``ee_axis``)."""
    flip = -np.ones(3)
    flip[AXIS_INDEX[arm.ee_axis]] = 1.0
    return np.asarray(R_ee, float) * flip  # R · diag(flip): the two other columns reversed


def grasp_side_shift(arm: ArmConfig, width: float) -> float:
    """Where the grasp centre lies across the ee_axis line, along the closing direction (m).

    0 for grippers whose jaws close symmetrically about the TCP. A one-jaw gripper pushes the
    object against its fixed jaw, so the object's centre ends ``fixed_jaw_face − width/2`` from
    the line (the moving jaw comes from the −closing side)."""
    g = arm.gripper
    if isinstance(g, OneJawGripperConfig):
        return float(g.fixed_jaw_face - width / 2)
    return 0.0


def ee_pose_from_grasp(grasp: Grasp, arm: ArmConfig, standoff: float = 0.0) -> np.ndarray:
    """World pose of ``ee_link`` that puts the TCP at the grasp centre (moved back along the
    approach by ``standoff`` metres), with ``world_R_ee = world_R_grasp · R_ee_graspnet``.
    For a one-jaw gripper the EE is also moved across by :func:`grasp_side_shift` at the grasp's
    width, so the fixed jaw's face lands on the object's side instead of inside it."""
    R_ee = grasp.rotation @ np.asarray(arm.R_ee_graspnet, float)  # numpy's product (its BLAS may fuse)
    center = np.asarray(grasp.center, float)
    if center.shape != (3,) or R_ee.shape != (3, 3):
        tcp = center - standoff * grasp.approach()
        tcp = tcp - grasp_side_shift(arm, grasp.width) * grasp.closing()
        T = np.eye(4)
        T[:3, :3] = R_ee
        T[:3, 3] = tcp - arm.tcp_offset * R_ee[:, AXIS_INDEX[arm.ee_axis]]
        return T
    # the rest in Python floats: each product and difference the one the arrays above make
    (g00, g01, _), (g10, g11, _), (g20, g21, _) = np.asarray(grasp.rotation, float).tolist()
    shift, off, k = grasp_side_shift(arm, grasp.width), arm.tcp_offset, AXIS_INDEX[arm.ee_axis]
    rows = R_ee.tolist()
    out = []
    for c, a, b, r in zip(center.tolist(), (g00, g10, g20), (g01, g11, g21), rows, strict=True):
        t = c - standoff * a
        t = t - shift * b
        out.append([*r, t - off * r[k]])
    out.append([0.0, 0.0, 0.0, 1.0])
    return np.array(out)


def tcp_from_ee(T_ee: np.ndarray, arm: ArmConfig) -> np.ndarray:
    """World pose of the TCP given the world pose of ``ee_link``."""
    T = np.array(T_ee, float)
    T[:3, 3] = T_ee[:3, 3] + arm.tcp_offset * T_ee[:3, AXIS_INDEX[arm.ee_axis]]
    return T


def top_down_grasps(center: np.ndarray, yaw: float, extent_xy: tuple[float, float]) -> list[Grasp]:
    """The two top-down grasps of an upright object with yaw ``yaw`` (rad) and horizontal extents
    (along its own x and y, m): approach straight down, fingers closing across the narrower side.
    The two differ by a half turn about the approach axis; callers pick the one closer to the
    current wrist orientation."""
    ex, ey = extent_xy
    axis_x = np.array([np.cos(yaw), np.sin(yaw), 0.0])
    axis_y = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
    closing, width = (axis_x, ex) if ex <= ey else (axis_y, ey)
    down = np.array([0.0, 0.0, -1.0])
    return [Grasp(np.asarray(center, float), grasp_rotation(down, s * closing), width) for s in (1.0, -1.0)]

