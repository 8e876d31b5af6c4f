"""Cross-checks of one arm of a robot YAML against its URDF: base and end-effector links, the
arm joints (names or DOF indices) forming the serial chain between them, ``R_ee_graspnet`` (a
rotation whose ``ee_axis`` column is the grasp approach x), home within the limits, collision
filter links, and the gripper: joints, open/closed positions, finger links, and the TCP against the
finger pads (by FK, in the ``ee_link`` frame, m). Suction and one-jaw tool points are checked in
:mod:`robocfg.checks.tool_point`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robocfg.assets.fingers import (
    FingerGeometryMissing,
    closing_axis,
    finger_points,
    pad_midpoint,
    pad_points,
)
from robocfg.assets.paths import Resolver
from robocfg.assets.urdf import Urdf
from robocfg.checks.tool_point import check_one_jaw, check_suction
from robocfg.config.load import Loc, YamlDocument
from robocfg.config.robot import (
    ArmConfig,
    OneJawGripperConfig,
    ParallelGripperConfig,
    SuctionGripperConfig,
)
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import Problem
from robocfg.suggest import did_you_mean

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot

ROT_TOL = 1e-6
TCP_WARN_DIST = 0.010  # m
TCP_WARN_ANGLE_DEG = 10.0
TCP_ERROR_ANGLE_DEG = 45.0  # past this, ee_axis does not point at the fingers at all: an error


class Collector:
    """Problems found so far, as errors or warnings at positions of the robot YAML."""

    def __init__(self, doc: YamlDocument):
        self.doc = doc
        self.problems: list[Problem] = []

    def error(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg))

    def warn(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg, "warning"))


def known(c: Collector, loc: Loc, name: str, names: list[str], kind: str) -> bool:
    if name in names:
        return True
    c.error(loc, f"no {kind} {name!r} in the URDF{did_you_mean(name, names)}")
    return False


def check_arm(c: Collector, robot: CheckedRobot, arm: ArmConfig, loc: Loc, resolver: Resolver) -> None:
    urdf = robot.urdf
    links = list(urdf.links)
    ok_links = known(c, (*loc, "base_link"), arm.base_link, links, "link")
    ok_links &= known(c, (*loc, "ee_link"), arm.ee_link, links, "link")
    names_ok = _check_joint_list(c, urdf, arm.joints, arm.joint_indices, loc, "joints", "joint_indices")
    if not names_ok:
        return
    arm_joints = robot.arm_joints(arm)
    if ok_links:
        chain = urdf.chain(arm.base_link, arm.ee_link)
        if chain is None:
            c.error((*loc, "ee_link"), f"ee_link {arm.ee_link!r} is not below base_link {arm.base_link!r} in the URDF tree")
        else:
            movable = [j.name for j in chain if j.movable]
            if movable != arm_joints:
                c.error((*loc, "joints" if arm.joints else "joint_indices"),
                        f"arm joints must form the serial chain of movable joints from base_link {arm.base_link!r} to ee_link {arm.ee_link!r}, in order: expected {movable}, got {arm_joints}")
    # R_ee_graspnet
    R = np.asarray(arm.R_ee_graspnet, dtype=float)
    if not np.allclose(R @ R.T, np.eye(3), atol=ROT_TOL) or abs(np.linalg.det(R) - 1) > ROT_TOL:
        c.error((*loc, "R_ee_graspnet"), f"must be a rotation (orthonormal, det +1); R·Rᵀ deviates by {np.abs(R @ R.T - np.eye(3)).max():.2e}, det = {np.linalg.det(R):.4f}")
    else:
        col = R[:, AXIS_INDEX[arm.ee_axis]]
        if not np.allclose(col, [1, 0, 0], atol=ROT_TOL):
            c.error((*loc, "R_ee_graspnet"),
                    f"column {AXIS_INDEX[arm.ee_axis]} (ee_axis '{arm.ee_axis}') must be (1, 0, 0): the EE approach axis is the grasp frame's x; got {np.round(col, 6).tolist()}")
    # home within limits
    for k, (jn, q) in enumerate(zip(arm_joints, arm.home, strict=True)):
        j = urdf.joints[jn]
        if j.type == "continuous":
            continue
        if not (j.lower - 1e-9 <= q <= j.upper + 1e-9):
            c.error((*loc, "home", k), f"home of {jn} = {q:.4f} is outside the limits [{j.lower:.4f}, {j.upper:.4f}]")
        elif arm.home_std is not None:
            s = 3 * arm.home_std[k]
            if q - s < j.lower or q + s > j.upper:
                c.warn((*loc, "home_std", k), f"home ± 3·std for {jn} ({q - s:.3f}..{q + s:.3f}) leaves the limits [{j.lower:.3f}, {j.upper:.3f}]")
    for key in ("ignore_links", "forbid_links"):
        for k, ln in enumerate(getattr(arm.collision_filter, key)):
            known(c, (*loc, "collision_filter", key, k), ln, links, "link")
    g = arm.gripper
    if isinstance(g, ParallelGripperConfig):
        _check_parallel(c, robot, arm, g, (*loc, "gripper"), resolver)
    elif isinstance(g, SuctionGripperConfig) and known(c, (*loc, "gripper", "link"), g.link, links, "link"):
        chain = urdf.chain(arm.ee_link, g.link) if arm.ee_link in links else []
        if chain is None or any(j.movable for j in chain):
            c.error((*loc, "gripper", "link"), f"suction link {g.link!r} must be rigidly attached below ee_link {arm.ee_link!r}")
        else:
            check_suction(c.warn, urdf, resolver, arm, g, (*loc, "tcp_offset"), (*loc, "gripper", "link"))


def _check_joint_list(c: Collector, urdf: Urdf, names: list[str] | None, indices: list[int] | None,
                      loc: Loc, name_key: str, index_key: str) -> bool:
    ok = True
    joints = list(urdf.joints)
    if names is not None:
        for k, n in enumerate(names):
            if not known(c, (*loc, name_key, k), n, joints, "joint"):
                ok = False
            elif not urdf.joints[n].movable:
                c.error((*loc, name_key, k), f"joint {n!r} is {urdf.joints[n].type}, not movable")
                ok = False
    if indices is not None:
        ndof = len(urdf.dof_joints)
        for k, i in enumerate(indices):
            if not 0 <= i < ndof:
                c.error((*loc, index_key, k), f"DOF index {i} is out of range: the URDF has {ndof} movable joints (0..{ndof - 1}){_pybullet_hint(urdf, i)}")
                ok = False
            elif names is not None and k < len(names) and urdf.dof_joints[i] != names[k]:
                c.error((*loc, index_key, k), f"DOF index {i} is {urdf.dof_joints[i]!r} but {name_key}[{k}] is {names[k]!r}{_pybullet_hint(urdf, i)}")
                ok = False
    return ok


def _pybullet_hint(urdf: Urdf, i: int) -> str:
    """Hint for the classic mistake of giving a PyBullet joint index (fixed joints counted)."""
    by_index = {j.urdf_index: j for j in urdf.joints.values()}
    j = by_index.get(i)
    if j is None:
        return ""
    if j.movable:
        return f"; PyBullet joint index {i} is {j.name!r}, whose DOF index is {urdf.dof_index(j.name)} (indices here are DOF indices, see `robocfg inspect`)"
    return f"; PyBullet joint index {i} is the {j.type} joint {j.name!r} (indices here are DOF indices: fixed joints have none, see `robocfg inspect`)"


def _check_parallel(c: Collector, robot: CheckedRobot, arm: ArmConfig, g: ParallelGripperConfig,
                    loc: Loc, resolver: Resolver) -> None:
    urdf = robot.urdf
    if not _check_joint_list(c, urdf, g.joints, g.gripper_indices, loc, "joints", "gripper_indices"):
        return
    leaders = robot.gripper_joints(arm)
    arm_joints = set(robot.arm_joints(arm)) if (arm.joints or arm.joint_indices) else set()
    key = "joints" if g.joints is not None else "gripper_indices"
    for k, jn in enumerate(leaders):
        j = urdf.joints[jn]
        if jn in arm_joints:
            c.error((*loc, key, k), f"gripper joint {jn!r} is also an arm joint")
        if arm.ee_link in urdf.descendants(jn):
            c.error((*loc, key, k), f"gripper joint {jn!r} moves ee_link {arm.ee_link!r}: the EE→TCP transform must be fixed; pick a link above the fingers")
        if j.mimic is not None:
            c.error((*loc, key, k), f"gripper joint {jn!r} is a mimic follower of {j.mimic.joint!r} (URDF <mimic>); list only the driven joint(s) — followers are geared automatically")
        for key in ("open", "closed"):
            v = getattr(g, key)[k]
            if not (j.lower - 1e-9 <= v <= j.upper + 1e-9):
                c.error((*loc, key, k), f"{key} position {v} of {jn} is outside the limits [{j.lower}, {j.upper}]")
    finger_ok = all(known(c, (*loc, "finger_links", k), f, list(urdf.links), "link") for k, f in enumerate(g.finger_links))
    if finger_ok and arm.ee_link in urdf.links:
        _check_tcp(c, robot, arm, g, leaders, loc, resolver)
        if isinstance(g, OneJawGripperConfig):
            check_one_jaw(c.warn, urdf, resolver, arm, g, leaders, loc)


def _check_tcp(c: Collector, robot: CheckedRobot, arm: ArmConfig, g: ParallelGripperConfig,
               leaders: list[str], loc: Loc, resolver: Resolver) -> None:
    """The finger-pad midpoint (by FK) must lie along +ee_axis, and ``tcp_offset`` within the range
    that midpoint covers between ``open`` and ``closed`` (± TCP_WARN_DIST): on linkage grippers
    (Robotiq) the pads move along the approach axis as they close, so the TCP depends on the width."""
    urdf = robot.urdf
    axis = AXIS_INDEX[arm.ee_axis]
    try:
        points = finger_points(urdf, resolver, list(g.finger_links))
    except FingerGeometryMissing as exc:
        if "no geometry" in str(exc):
            c.warn((*loc, "finger_links"), f"{exc}; cannot check tcp_offset")
        return  # a missing mesh is already reported
    mids = [pad_midpoint(pad_points(urdf, arm.ee_link, list(g.finger_links), points, dict(zip(leaders, qs, strict=True)), axis))
            for qs in (g.open, g.closed)]
    mid = mids[0].copy()
    if isinstance(g, OneJawGripperConfig):  # its grasp centre is off the axis by design (grasp_side_shift)
        c_dir = closing_axis(arm.R_ee_graspnet)
        mid -= (mid @ c_dir) * c_dir
    along = mid[axis]
    angle = np.degrees(np.arccos(np.clip(along / max(np.linalg.norm(mid), 1e-9), -1, 1)))
    lo, hi = sorted(float(m[axis]) for m in mids)
    tcp_loc = ("arms", robot.config.arms.index(arm), "tcp_offset")
    span = f"{along:.4f} m" if hi - lo < 1e-4 else f"{mids[0][axis]:.4f} m open, {mids[1][axis]:.4f} m closed"
    if along <= 0 or angle > TCP_ERROR_ANGLE_DEG:
        c.error((*loc[:-1], "ee_axis"), f"the finger pads (gripper open) are {angle:.0f}° away from +{arm.ee_axis} of ee_link "
                f"(midpoint {np.round(mid, 4).tolist()} m in the ee_link frame); ee_axis must point from ee_link towards the fingertips")
    elif not lo - TCP_WARN_DIST <= arm.tcp_offset <= hi + TCP_WARN_DIST or angle > TCP_WARN_ANGLE_DEG:
        c.warn(tcp_loc, f"finger-pad midpoint is {span} along {arm.ee_axis} and {angle:.1f}° off the axis; tcp_offset is {arm.tcp_offset:.4f} m")
