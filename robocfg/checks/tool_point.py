"""Checks of a gripper's working point against its geometry (pure FK on the URDF, no simulator).

* one-jaw grippers: ``fixed_jaw_face`` against the fixed jaw's inner face, measured on its pad
  (the distal part of its collision geometry, as for parallel fingers);
* suction: ``tcp_offset`` against the cup face — the point of the suction link's geometry
  furthest along ``ee_axis`` — since a TCP past the cup makes every pick press the object away
  and one short of it never touches.

Frames: the ``ee_link`` frame, metres. Problems go to the caller's collector (``warn``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from robocfg.assets.fingers import FingerGeometryMissing, closing_axis, finger_points, pad_points
from robocfg.config.types import AXIS_INDEX

if TYPE_CHECKING:
    from robocfg.assets.paths import Resolver
    from robocfg.assets.urdf import Urdf
    from robocfg.config.robot import ArmConfig, OneJawGripperConfig, SuctionGripperConfig

FACE_WARN_DIST = 0.005  # m: fixed_jaw_face off the measured face by more than this is warned
CUP_WARN_DIST = 0.010  # m: tcp_offset off the cup face by more than this is warned

Warn = Callable[[tuple, str], None]


def fixed_jaw_face(urdf: Urdf, resolver: Resolver, arm: ArmConfig, g: OneJawGripperConfig,
                   q: dict[str, float]) -> float:
    """Measured position (m) of the fixed jaw's inner face along the closing direction, from the
    ee_axis line: the fixed pad's side facing the moving jaw (which closes along +closing)."""
    axis = AXIS_INDEX[arm.ee_axis]
    links = list(g.finger_links)
    pads = pad_points(urdf, arm.ee_link, links, finger_points(urdf, resolver, links), q, axis)
    return float((pads[1] @ closing_axis(arm.R_ee_graspnet)).min())


def check_one_jaw(warn: Warn, urdf: Urdf, resolver: Resolver, arm: ArmConfig, g: OneJawGripperConfig,
                  leaders: list[str], loc: tuple) -> None:
    """Warn when ``fixed_jaw_face`` is off the measured face, or the moving jaw does not close
    towards the fixed one along the closing direction."""
    q_open = dict(zip(leaders, g.open, strict=True))
    q_closed = dict(zip(leaders, g.closed, strict=True))
    try:
        face = fixed_jaw_face(urdf, resolver, arm, g, q_open)
        axis = AXIS_INDEX[arm.ee_axis]
        links = list(g.finger_links)
        pts = finger_points(urdf, resolver, links)
        c = closing_axis(arm.R_ee_graspnet)
        moving = [float((pad_points(urdf, arm.ee_link, links, pts, q, axis)[0] @ c).mean()) for q in (q_open, q_closed)]
    except FingerGeometryMissing as exc:
        warn((*loc, "finger_links"), f"{exc}; cannot check fixed_jaw_face")
        return
    if abs(face - g.fixed_jaw_face) > FACE_WARN_DIST:
        warn((*loc, "fixed_jaw_face"), f"the fixed jaw's inner face ({g.finger_links[1]}) is measured at {face:.4f} m along "
             f"the closing direction, fixed_jaw_face is {g.fixed_jaw_face:.4f} m")
    if moving[1] <= moving[0]:
        warn((*loc, "finger_links"), f"the moving jaw {g.finger_links[0]!r} does not move along the closing direction "
             "(R_ee_graspnet row 1) when closing: list [moving jaw, fixed jaw] and point grasp y from the moving jaw to the fixed one")


def cup_face(urdf: Urdf, resolver: Resolver, arm: ArmConfig, g: SuctionGripperConfig) -> float | None:
    """Distance (m) along ``ee_axis`` from ``ee_link`` to the cup face (the suction link's geometry
    furthest along the axis); None when the link has no geometry."""
    try:
        (P,) = finger_points(urdf, resolver, [g.link])
    except FingerGeometryMissing:
        return None
    T = np.linalg.inv(urdf.link_pose(arm.ee_link)) @ urdf.link_pose(g.link)
    return float((P @ T[:3, :3].T + T[:3, 3])[:, AXIS_INDEX[arm.ee_axis]].max())


def check_suction(warn: Warn, urdf: Urdf, resolver: Resolver, arm: ArmConfig, g: SuctionGripperConfig,
                  tcp_loc: tuple, link_loc: tuple) -> None:
    """Warn when ``tcp_offset`` is not at the cup face (± CUP_WARN_DIST)."""
    face = cup_face(urdf, resolver, arm, g)
    if face is None:
        warn(link_loc, f"suction link {g.link!r} has no geometry; cannot check tcp_offset against the cup face")
    elif abs(face - arm.tcp_offset) > CUP_WARN_DIST:
        warn(tcp_loc, f"the TCP of a suction gripper is the cup face, measured at {face:.4f} m along {arm.ee_axis} "
             f"of {arm.ee_link}; tcp_offset is {arm.tcp_offset:.4f} m")


HINT_TCP_DIST = 0.003  # m: a tcp_offset this far from the closed pad midpoint is named as the likely cause
NOTHING_GAP = 0.002  # m: fingers within this of min_width closed on nothing


def pad_midpoints(urdf: Urdf, resolver: Resolver, arm: ArmConfig, leaders: list[str]) -> tuple[float, float] | None:
    """(open, closed) distance (m) of the finger-pad midpoint along ``ee_axis`` — what ``validate``
    measures — or None without a finger gripper or finger geometry."""
    from robocfg.config.robot import ParallelGripperConfig

    g = arm.gripper
    if not isinstance(g, ParallelGripperConfig):
        return None
    axis = AXIS_INDEX[arm.ee_axis]
    links = list(g.finger_links)
    try:
        pts = finger_points(urdf, resolver, links)
    except FingerGeometryMissing:
        return None
    from robocfg.assets.fingers import pad_midpoint

    o, c = (float(pad_midpoint(pad_points(urdf, arm.ee_link, links, pts, dict(zip(leaders, q, strict=True)), axis))[axis])
            for q in (g.open, g.closed))
    return o, c


def grasp_failure_hint(urdf: Urdf, resolver: Resolver, arm: ArmConfig, leaders: list[str], width: float | None) -> str:
    """The likely cause of a grasp that did not hold, for the failure message: the fingers closed
    on nothing (``width`` at the closed gap) or the object slipped, and — when ``tcp_offset`` is
    off the closed pad midpoint — ``check tcp_offset (now 0.130 m, pads measured at 0.144 m closed)``."""
    from robocfg.config.robot import ParallelGripperConfig

    g = arm.gripper
    if not isinstance(g, ParallelGripperConfig):
        return ""
    what = "fingers closed on nothing" if width is not None and width <= g.min_width + NOTHING_GAP else "object slipped"
    mids = pad_midpoints(urdf, resolver, arm, leaders)
    if mids is not None and abs(mids[1] - arm.tcp_offset) > HINT_TCP_DIST:
        return (f"{what}: check tcp_offset (now {arm.tcp_offset:.3f} m, pads measured at {mids[1]:.3f} m closed"
                + (f", {mids[0]:.3f} m open)" if abs(mids[0] - mids[1]) > 1e-3 else ")"))
    return f"{what}: check the grip force (gripper.max_force {g.max_force:g}), the friction and the object's width"
