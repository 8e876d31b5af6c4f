"""Measure a gripper's links as boxes in the grasp frame, from PyBullet's collision shapes.

For every link at or below ``ee_link`` that has a collision shape: its axis-aligned box in the
grasp frame and an oriented box in the link's own (inertial) frame, read from the mesh vertices
(PyBullet's ``getMeshData``) or primitive corners. The grasp planner turns these measurements
into its :class:`robocfg.grasp.gripper_model.GripperBoxes`; this module is the only part of that
model that talks to the simulator. Lengths in metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
import pybullet as p

from robocfg.config.robot import ParallelGripperConfig
from robocfg.geometry import pose_to_matrix

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle, RobotHandle


class OrientedBox(NamedTuple):
    """A link's box: ``R``, ``t`` its frame in the grasp frame, ``lo``, ``hi`` its corners in its own
    frame (m); ``touches``: a finger or a link a finger is fixed to (it may touch the object)."""

    R: np.ndarray
    t: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    touches: bool


@dataclass(frozen=True)
class LinkBoxes:
    """One measurement of the gripper: per link, ``lo``/``hi`` (B, 3) of its box in the grasp frame
    (m), its name, whether it is a finger link, and its oriented box."""

    lo: np.ndarray
    hi: np.ndarray
    names: tuple[str, ...]
    finger: np.ndarray
    obbs: tuple[OrientedBox, ...]


@dataclass(frozen=True)
class GripperLayout:
    """What measuring ``arm``'s gripper reads from PyBullet that its joints do not change: the
    links (``ee_link`` first, then those below it), the finger links and the links a finger is
    fixed to, and each link's collision shapes (:func:`_shape_points`: points, m, and the shape's
    pose in the link's inertial frame, None for a mesh)."""

    links: tuple[int, ...]
    fingers: frozenset[str]
    touching: frozenset[str]
    shapes: tuple[tuple[tuple[np.ndarray, np.ndarray | None], ...], ...]


def gripper_layout(robot: RobotHandle, arm: ArmHandle) -> GripperLayout:
    """The :class:`GripperLayout` of ``arm``'s gripper (read once for a series of measurements)."""
    c, body = robot.client, robot.body_id
    cfg = arm.config
    ee = robot.link(cfg.ee_link)
    links = (ee, *_links_below(c, body, ee))
    fingers = set(cfg.gripper.finger_links) if isinstance(cfg.gripper, ParallelGripperConfig) else set()
    touching = fingers | _rigid_parents(robot, fingers)
    return GripperLayout(links, frozenset(fingers), frozenset(touching), tuple(_shape_points(c, body, li) for li in links))


def measure_link_boxes(robot: RobotHandle, arm: ArmHandle, grasp_T_ee: np.ndarray,
                       layout: GripperLayout | None = None) -> LinkBoxes:
    """Boxes of ``arm``'s gripper links in its current state; ``grasp_T_ee`` (4x4) places the grasp
    frame relative to ``ee_link``; ``layout``: :func:`gripper_layout` of this arm, read earlier
    (default: read now). Raises ValueError when no finger link has a collision shape."""

    c, body = robot.client, robot.body_id
    if layout is None:
        layout = gripper_layout(robot, arm)
    T_ee = arm.ee_pose()
    G_T_world = grasp_T_ee @ np.linalg.inv(T_ee)
    fingers, touching = layout.fingers, layout.touching
    lo, hi, names, finger, obbs = [], [], [], [], []
    for li, shapes in zip(layout.links, layout.shapes, strict=True):
        pts, T_com = _collision_points(c, body, li, shapes)
        if len(pts) == 0:
            continue
        g = pts @ G_T_world[:3, :3].T + G_T_world[:3, 3]
        lo.append(g.min(axis=0))
        hi.append(g.max(axis=0))
        local = (pts - T_com[:3, 3]) @ T_com[:3, :3]
        G_T_link = G_T_world @ T_com
        name = robot.link_name(li)
        obbs.append(OrientedBox(G_T_link[:3, :3], G_T_link[:3, 3], local.min(axis=0), local.max(axis=0), name in touching))
        names.append(name)
        finger.append(name in fingers)
    if not any(finger):
        raise ValueError(f"no collision shape found on the finger links {sorted(fingers)}")
    return LinkBoxes(np.array(lo), np.array(hi), tuple(names), np.array(finger), tuple(obbs))


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


def _shape_points(client: int, body: int, link: int) -> tuple[tuple[np.ndarray, np.ndarray | None], ...]:
    """The collision shapes of ``link``: per shape, its points (mesh vertices from PyBullet's
    ``getMeshData``, given in the link's inertial frame; primitive-shape corners in the shape's
    frame otherwise) and the shape's pose in the inertial frame (None for a mesh). The same
    whatever the joints' state: a shape's vertices are stored in its own frame."""
    out: list[tuple[np.ndarray, np.ndarray | None]] = []
    for k, s in enumerate(p.getCollisionShapeData(body, link, physicsClientId=client)):
        if s[2] == p.GEOM_MESH:
            n, verts = p.getMeshData(body, link, collisionShapeIndex=k, physicsClientId=client)[:2]
            out.append((np.asarray(verts, float).reshape(-1, 3) if n else np.zeros((0, 3)), None))
        else:
            out.append((_primitive_corners(s[2], s[3]), pose_to_matrix(s[5], s[6])))
    return tuple(out)


def _collision_points(client: int, body: int, link: int,
                      shapes: tuple[tuple[np.ndarray, np.ndarray | None], ...]) -> tuple[np.ndarray, np.ndarray]:
    """World points spanning the collision ``shapes`` of ``link`` (:func:`_shape_points`) and the
    world pose of the link's inertial frame."""
    if not shapes:
        return np.zeros((0, 3)), np.eye(4)
    if link >= 0:
        st = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=client)
        T_com = pose_to_matrix(st[0], st[1])
    else:
        pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=client)
        T_com = pose_to_matrix(pos, orn)
    out = []
    for local, pose in shapes:
        T = T_com if pose is None else T_com @ pose
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
