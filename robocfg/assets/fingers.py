"""Finger-pad geometry of a parallel gripper from its URDF (pure FK on collision geometry, no simulator).

The *pad* of a finger link is the distal ``PAD_LENGTH`` of its geometry along the approach axis
(``ee_axis``), or the whole link when the link is itself a pad (no longer than ``2·PAD_LENGTH``
along that axis, like the Robotiq 2F-85's ``*_inner_finger_pad`` boxes). Frames: every point is in
the ``ee_link`` frame, metres. Gripper joint values: driven (leader) joints by name; mimic
followers follow (``Urdf.link_pose``).
"""

from __future__ import annotations

import numpy as np

from robocfg.assets.meshes import geometry_points
from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf import Urdf

PAD_LENGTH = 0.02  # m: the distal part of a finger counted as its pad


class FingerGeometryMissing(Exception):
    """A finger link without usable geometry (``link`` names it)."""

    def __init__(self, link: str, why: str):
        self.link = link
        super().__init__(f"finger link {link!r} {why}")


def finger_points(urdf: Urdf, resolver: Resolver, finger_links: list[str]) -> list[np.ndarray]:
    """(N, 3) geometry points of each finger link in its own link frame (collision, else visual)."""
    out = []
    for name in finger_links:
        link = urdf.links[name]
        pts = []
        for geom in link.collisions or link.visuals:
            mesh = None
            if geom.kind == "mesh":
                try:
                    mesh = resolver.mesh(geom.filename or "", urdf.path)
                except UnresolvedPath:
                    raise FingerGeometryMissing(name, f"has a mesh that cannot be found: {geom.filename}") from None
            pts.append(geometry_points(geom, mesh))
        if not pts or not len(np.concatenate(pts)):
            raise FingerGeometryMissing(name, "has no geometry")
        out.append(np.concatenate(pts))
    return out


def pad_points(urdf: Urdf, ee_link: str, finger_links: list[str], points: list[np.ndarray],
               q: dict[str, float], axis: int, memo: dict | None = None,
               ee_inv: np.ndarray | None = None) -> list[np.ndarray]:
    """Pad points of each finger in the ``ee_link`` frame at gripper joint values ``q``
    (``memo``: :meth:`Urdf.link_pose`'s, kept over a sweep of ``q``; ``ee_inv``: the inverse of
    ``ee_link``'s pose at ``q`` when the caller has it, e.g. one for a whole sweep of joints that do
    not move ``ee_link``)."""
    T_ee_inv = np.linalg.inv(urdf.link_pose(ee_link, q, memo)) if ee_inv is None else ee_inv
    out = []
    for name, P in zip(finger_links, points, strict=True):
        T = T_ee_inv @ urdf.link_pose(name, q, memo)
        P_ee = P @ T[:3, :3].T + T[:3, 3]
        tip, base = P_ee[:, axis].max(), P_ee[:, axis].min()
        if tip - base <= 2 * PAD_LENGTH:
            out.append(P_ee)
            continue
        # The distal points, plus their copies moved back to the pad's start: the pad spans the whole
        # PAD_LENGTH along the axis even when the geometry has no vertex there (a box's corners).
        pad = P_ee[P_ee[:, axis] >= tip - PAD_LENGTH]
        back = pad.copy()
        back[:, axis] = tip - PAD_LENGTH
        out.append(np.vstack([pad, back]))
    return out


def pad_midpoint(pads: list[np.ndarray]) -> np.ndarray:
    """Midpoint (ee_link frame, m) between the centres of the two pads' bounding boxes."""
    centres = [(P.min(axis=0) + P.max(axis=0)) / 2 for P in pads]
    return (centres[0] + centres[1]) / 2


def pad_gap(pads: list[np.ndarray], closing: np.ndarray) -> float:
    """Gap (m) between the two pads' facing sides along the unit ``closing`` direction (ee frame)."""
    a, b = (P @ closing for P in pads)
    return float(max(b.min() - a.max(), a.min() - b.max()))


def closing_axis(R_ee_graspnet) -> np.ndarray:
    """The finger closing direction (grasp-frame y) in the ee_link frame: row 1 of ``R_ee_graspnet``."""
    return np.asarray(R_ee_graspnet, dtype=float)[1]


def width_curve(urdf: Urdf, resolver: Resolver, ee_link: str, ee_axis: int, finger_links: list[str],
                leaders: list[str], q_open, q_closed, closing: np.ndarray, n: int = 33) -> tuple[np.ndarray, np.ndarray]:
    """Pad gap (m) at ``n`` opening fractions s ∈ [0, 1] (0 = ``q_closed``, 1 = ``q_open``, driven
    joints interpolated linearly, followers by their mimic tags): returns (s, gap). On linkage
    grippers the gap is not linear in the joint; this curve lets a width command be inverted."""
    points = finger_points(urdf, resolver, finger_links)
    qo, qc = np.asarray(q_open, float), np.asarray(q_closed, float)
    s = np.linspace(0.0, 1.0, n)
    memo: dict = {}  # the arm's chain to the hand is the same at every s
    qs = [dict(zip(leaders, qc + k * (qo - qc), strict=True)) for k in s]
    # ee_link's pose does not change over the sweep unless a swept joint (a leader or one of its
    # mimic followers) is on its chain: then its inverse is the same at every s, computed once
    moved = {j.name for j in urdf.joints.values() if j.name in leaders or (j.mimic is not None and j.mimic.joint in leaders)}
    fixed = not any(j.name in moved for j in urdf.chain(urdf.root, ee_link) or [])
    ee_inv = np.linalg.inv(urdf.link_pose(ee_link, qs[0], memo)) if fixed and qs else None
    gaps = np.array([pad_gap(pad_points(urdf, ee_link, finger_links, points, q, ee_axis, memo, ee_inv), closing)
                     for q in qs])
    return s, gaps
