"""A box model of the gripper in the grasp frame, measured from the robot's own collision shapes.

Every link rigidly or movably attached below ``ee_link`` (and ``ee_link`` itself) becomes one
axis-aligned box in the GraspNet grasp frame (origin at the TCP, x = approach, y = closing,
z = x × y; design.md §3), measured with the gripper open, and again at ``CLOSING_SAMPLES``
openings down to closed (with an oriented box per link, for linkages). No per-robot numbers: the
boxes come from PyBullet's collision shapes (mesh vertices and primitive corners), so any robot
YAML works. A cloud point inside a box means the gripper would hit it; extending the boxes back
along −x by the pre-grasp stand-off covers the straight approach too.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet as p

from robocfg.geometry import pose_to_matrix

CLOSING_SAMPLES = 9  # openings measured from open to closed (a Robotiq's pads move ≈ 10 mm between samples)
CLOSING_TOLERANCE = 0.005  # m: a sample this much narrower than the grasp width still counts as reached


@dataclass(frozen=True)
class GripperBoxes:
    """``lo``, ``hi`` (B, 3): box corners in the grasp frame (m); ``names``: link per box;
    ``finger``: which boxes are finger links; ``max_width``: open finger gap (m)."""

    lo: np.ndarray
    hi: np.ndarray
    names: tuple[str, ...]
    finger: np.ndarray
    max_width: float
    samples: tuple = ()  # (gap m, lo, hi, oriented boxes) from open to closed: linkages such as
    # the Robotiq's swing their pads forward as they close, so what sweeps below the TCP depends on width

    def linkage_hits(self, points_g: np.ndarray, width: float, margin: float) -> bool:
        """True if a non-finger link, at any measured opening down to ``width`` (m), has one of
        ``points_g`` (N, 3, grasp frame) inside its oriented box grown by ``margin``."""
        for gap, _, _, obbs in self.samples:
            if gap < width:
                continue
            for R, t, lo, hi, touches in obbs:
                if touches:
                    continue
                local = (points_g - t) @ R
                if np.any(np.all((local >= lo - margin) & (local <= hi + margin), axis=1)):
                    return True
        return False

    def closing_sweep(self, width: float | None = None) -> GripperBoxes:
        """Each link's box grown to cover it from open until the fingers reach ``width`` (m;
        None: fully closed) — for support-plane checks of the closing motion."""
        lo, hi = self.lo.copy(), self.hi.copy()
        for gap, s_lo, s_hi, _ in self.samples:
            if width is None or gap >= width - CLOSING_TOLERANCE:
                lo, hi = np.minimum(lo, s_lo), np.maximum(hi, s_hi)
        return GripperBoxes(lo, hi, self.names, self.finger, self.max_width)

    def swept(self, standoff: float) -> GripperBoxes:
        """Boxes covering the straight motion from ``standoff`` m back along the approach."""
        lo = self.lo.copy()
        lo[:, 0] -= standoff
        return GripperBoxes(lo, self.hi, self.names, self.finger, self.max_width, self.samples)

    def inflated(self, margin: float) -> GripperBoxes:
        return GripperBoxes(self.lo - margin, self.hi + margin, self.names, self.finger, self.max_width, self.samples)

    def finger_depth(self) -> tuple[float, float]:
        """Approach-axis extent (x range, m) of the fingers: where they can touch the object."""
        return float(self.lo[self.finger, 0].max()), float(self.hi[self.finger, 0].min())

    def finger_height(self) -> tuple[float, float]:
        """z range (m) shared by the fingers (their width across the closing direction)."""
        return float(self.lo[self.finger, 2].max()), float(self.hi[self.finger, 2].min())


def measure_gripper(robot, arm) -> GripperBoxes:
    """Boxes of ``arm``'s gripper measured open, then at ``CLOSING_SAMPLES`` openings down to closed
    (the gripper is teleported and back open: call it before taking a snapshot). Links without a
    collision shape are skipped; finger links are the gripper's ``finger_links``."""
    g = arm.gripper
    lo, hi, names, finger, obbs = _measure(robot, arm)
    samples = [(_gap(lo, hi, finger), lo, hi, obbs)]
    if g is not None and hasattr(g, "reset"):
        for f in np.linspace(1.0, 0.0, CLOSING_SAMPLES)[1:]:
            g.reset(float(f))
            s_lo, s_hi, s_names, _, s_obbs = _measure(robot, arm)
            if s_names == names:
                samples.append((_gap(s_lo, s_hi, finger), s_lo, s_hi, s_obbs))
        g.reset(1.0)
    max_width = float(getattr(arm.config.gripper, "max_width", 0.0))
    return GripperBoxes(lo, hi, names, finger, max_width, tuple(samples))


def _gap(lo: np.ndarray, hi: np.ndarray, finger: np.ndarray) -> float:
    """Gap (m) between the finger boxes along the closing axis (y), 0 when they overlap."""
    lo_y, hi_y = lo[finger, 1], hi[finger, 1]
    pos, neg = lo_y[lo_y + hi_y > 0], hi_y[lo_y + hi_y < 0]
    return max(0.0, float(pos.min() - neg.max())) if len(pos) and len(neg) else 0.0


def _measure(robot, arm) -> tuple[np.ndarray, np.ndarray, tuple[str, ...], np.ndarray, tuple]:
    """Per link with a collision shape: its AABB in the grasp frame (lo, hi), name, whether it is a
    finger, and an oriented box ``(G_R_link, G_t_link, local lo, local hi, touches)`` in its own
    frame (``touches``: a finger or a link a finger is fixed to — it may touch the object)."""
    c, body = robot.client, robot.body_id
    cfg = arm.config
    ee = robot.link(cfg.ee_link)
    below = _links_below(c, body, ee)
    T_ee = arm.ee_pose()
    G_T_world = _grasp_from_ee(cfg) @ np.linalg.inv(T_ee)
    fingers = set(getattr(cfg.gripper, "finger_links", []) or [])
    touching = fingers | _rigid_parents(robot, fingers)
    lo, hi, names, finger, obbs = [], [], [], [], []
    for li in [ee, *below]:
        pts, T_com = _collision_points(c, body, li)
        if len(pts) == 0:
            continue
        g = pts @ G_T_world[:3, :3].T + G_T_world[:3, 3]
        lo.append(g.min(axis=0))
        hi.append(g.max(axis=0))
        local = (pts - T_com[:3, 3]) @ T_com[:3, :3]
        G_T_link = G_T_world @ T_com
        name = robot.link_name(li)
        obbs.append((G_T_link[:3, :3], G_T_link[:3, 3], local.min(axis=0), local.max(axis=0), name in touching))
        names.append(name)
        finger.append(name in fingers)
    if not any(finger):
        raise ValueError(f"no collision shape found on the finger links {sorted(fingers)}")
    return np.array(lo), np.array(hi), tuple(names), np.array(finger), tuple(obbs)


def _rigid_parents(robot, links: set[str]) -> set[str]:
    """Links a finger link is fixed to (e.g. a Robotiq pad's inner finger): they touch the object
    with it, so they count as fingers."""
    out = set()
    for name in links:
        i = robot.link_index.get(name)
        if i is None or i < 0:
            continue
        info = p.getJointInfo(robot.body_id, i, physicsClientId=robot.client)
        if info[2] == p.JOINT_FIXED and info[16] >= 0:
            out.add(robot.link_name(info[16]))
    return out


def _grasp_from_ee(cfg) -> np.ndarray:
    """grasp_T_ee (4x4): world_R_ee = world_R_grasp · R_ee_graspnet, TCP at tcp_offset along ee_axis."""
    from robocfg.config.types import AXIS_INDEX

    R = np.asarray(cfg.R_ee_graspnet, float)
    tcp = np.zeros(3)
    tcp[AXIS_INDEX[cfg.ee_axis]] = cfg.tcp_offset
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = -R @ tcp
    return T


def _links_below(client: int, body: int, link: int) -> list[int]:
    parent = {j: p.getJointInfo(body, j, physicsClientId=client)[16] for j in range(p.getNumJoints(body, physicsClientId=client))}
    out = []
    for j in parent:
        k = j
        while k >= 0 and k != link:
            k = parent[k]
        if k == link and j != link:
            out.append(j)
    return out


def _collision_points(client: int, body: int, link: int) -> tuple[np.ndarray, np.ndarray]:
    """World points spanning the collision shapes of ``link`` (mesh vertices from PyBullet's
    ``getMeshData``, given in the link's inertial frame; primitive-shape corners otherwise) and
    the world pose of that inertial frame."""
    shapes = p.getCollisionShapeData(body, link, physicsClientId=client)
    if not shapes:
        return np.zeros((0, 3)), np.eye(4)
    if link >= 0:
        st = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=client)
        T_com = pose_to_matrix(st[0], st[1])
    else:
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        T_com = pose_to_matrix(pos, orn)
    out = []
    for k, s in enumerate(shapes):
        if s[2] == p.GEOM_MESH:
            n, verts = p.getMeshData(body, link, collisionShapeIndex=k, physicsClientId=client)[:2]
            local = np.asarray(verts, float).reshape(-1, 3) if n else np.zeros((0, 3))
            T = T_com
        else:
            local = _primitive_corners(s[2], s[3])
            T = T_com @ pose_to_matrix(s[5], s[6])
        if len(local):
            out.append(local @ T[:3, :3].T + T[:3, 3])
    return (np.concatenate(out) if out else np.zeros((0, 3))), T_com


def _primitive_corners(kind: int, dims) -> np.ndarray:
    d = np.asarray(dims, float)
    if kind == p.GEOM_BOX:
        h = d / 2
    elif kind == p.GEOM_SPHERE:
        h = np.full(3, d[0])
    elif kind in (p.GEOM_CYLINDER, p.GEOM_CAPSULE):
        length, r = d[0], d[1]
        h = np.array([r, r, length / 2 + (r if kind == p.GEOM_CAPSULE else 0.0)])
    else:
        return np.zeros((0, 3))
    return np.array([[sx * h[0], sy * h[1], sz * h[2]] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
