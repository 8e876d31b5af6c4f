"""Does the pick-place object fit the gripper? Checked on the object's real geometry (primitive,
mesh file or URDF, as it lies) against the finger gap measured on the robot's URDF, before any
simulation. Widths in metres."""

from __future__ import annotations

import numpy as np

from robocfg.assets.fingers import (
    FingerGeometryMissing,
    closing_axis,
    finger_points,
    pad_gap,
    pad_points,
)
from robocfg.assets.object_shape import FINGER_CLEARANCE, object_shape
from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.checks.robot import CheckedRobot
from robocfg.config.load import YamlDocument
from robocfg.config.robot import ArmConfig, ParallelGripperConfig
from robocfg.config.task import PickPlaceTask
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import Problem
from robocfg.geometry import quat_to_matrix


def measured_open_gap(robot: CheckedRobot, arm: ArmConfig) -> float | None:
    """Gap (m) between the finger pads with the gripper open, by FK on the URDF's finger geometry;
    None when the fingers have no usable geometry."""
    g = arm.gripper
    if not isinstance(g, ParallelGripperConfig):
        return None
    try:
        resolver = Resolver(robot.path.parent, robot.config.package_dirs)
        points = finger_points(robot.urdf, resolver, list(g.finger_links))
        q = dict(zip(robot.gripper_joints(arm), g.open, strict=True))
        pads = pad_points(robot.urdf, arm.ee_link, list(g.finger_links), points, q, AXIS_INDEX[arm.ee_axis])
    except (FingerGeometryMissing, KeyError, ValueError):
        return None
    gap = pad_gap(pads, closing_axis(arm.R_ee_graspnet))
    return gap if gap > 0 else None


def check_object_fit(doc: YamlDocument, task: PickPlaceTask, robot: CheckedRobot, arm: ArmConfig) -> list[Problem]:
    """One problem when the object is wider, in every horizontal direction, than the open fingers
    take (configured ``max_width`` or measured pad gap, whichever is smaller, less a clearance on
    each side); none for suction grippers. For a mesh the width is its convex hull's, so a
    concave object (a handle, a duck's neck) may still be grasped by a part: a warning then."""
    g = arm.gripper
    if not isinstance(g, ParallelGripperConfig):
        return []
    obj = task.pick_place.object
    loc = ("pick_place", "object", "mesh" if obj.shape == "mesh" else "size")
    try:
        shape = object_shape(obj, doc.path.parent)
    except UnresolvedPath:
        return []  # the missing file is reported by the mesh check
    except ValueError as exc:
        return [doc.problem(loc, f"cannot read the object's geometry: {exc}")]
    narrow = shape.min_horizontal_width(quat_to_matrix(obj.quaternion_xyzw()))
    gap = measured_open_gap(robot, arm)
    usable = min(g.max_width, gap if gap is not None else np.inf) - 2 * FINGER_CLEARANCE
    if narrow <= usable:
        return []
    measured = f", pads measured {gap * 1000:.1f} mm apart" if gap is not None else ""
    why = (f"object {obj.name!r} is {narrow * 1000:.1f} mm across its narrowest horizontal side "
           f"(from its geometry); the open gripper takes {usable * 1000:.1f} mm "
           f"(max_width {g.max_width * 1000:.1f} mm{measured}, less {FINGER_CLEARANCE * 1000:.0f} mm each side)")
    if obj.shape == "mesh":
        return [doc.problem(loc, f"{why}; only a narrower part of the mesh can be grasped, if it has one", "warning")]
    return [doc.problem(loc, why)]
