"""A light URDF model: links, joints, limits, mimic tags, geometry, inertials, as read by
:func:`robocfg.assets.urdf_xml.parse_urdf` (xml.etree).

Fast enough for ``robocfg validate`` (no trimesh, no simulator). DOF indices follow the order of
movable joints in the file, the same order PyBullet uses for its joint indices.

Why not yourdfpy (used by the browser viewer) or pinocchio: a problem in a URDF is reported at
its line (``panda.urdf:42:``), which needs the XML parser's positions; yourdfpy imports trimesh
(seconds of start-up for ``validate``, see ``robocfg.assets.meshes``), and pinocchio belongs to
the kinematics layer above this one. ``Urdf.link_pose`` is the few lines of forward kinematics
the URDF checks need (finger pads, TCP) before any kinematic model exists.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.geometry import axis_angle_matrix

MOVABLE = ("revolute", "continuous", "prismatic")


class UrdfParseError(Exception):
    """The URDF could not be parsed; ``line`` is set when known."""

    def __init__(self, message: str, line: int | None = None):
        self.line = line
        super().__init__(message)


@dataclass(frozen=True)
class Geometry:
    """One visual/collision geometry: ``kind`` box|sphere|cylinder|capsule|mesh, origin in the link frame."""

    kind: str
    origin: np.ndarray  # 4x4, link frame
    size: tuple[float, ...] = ()
    filename: str | None = None
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)


@dataclass(frozen=True)
class Link:
    name: str
    mass: float | None
    visuals: tuple[Geometry, ...]
    collisions: tuple[Geometry, ...]


@dataclass(frozen=True)
class Mimic:
    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class Joint:
    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray  # 4x4, parent link frame → joint frame
    axis: np.ndarray  # unit 3-vector in the joint frame
    lower: float
    upper: float
    effort: float
    velocity: float
    mimic: Mimic | None
    urdf_index: int  # position among all joints (PyBullet joint index)
    damping: float = 0.0  # <dynamics damping>: N·m·s/rad (N·s/m), which PyBullet applies
    friction: float = 0.0  # <dynamics friction>: N·m (N)

    @property
    def movable(self) -> bool:
        return self.type in MOVABLE


@dataclass
class Urdf:
    """Parsed URDF."""

    path: Path
    name: str
    links: dict[str, Link]
    joints: dict[str, Joint]
    root: str
    dof_joints: list[str] = field(default_factory=list)

    def dof_index(self, joint: str) -> int:
        return self.dof_joints.index(joint)

    def joint_to_child(self, link: str) -> Joint | None:
        for j in self.joints.values():
            if j.child == link:
                return j
        return None

    def chain(self, base: str, tip: str) -> list[Joint] | None:
        """Joints from ``base`` down to ``tip`` (all types), or None if tip is not below base."""
        out: list[Joint] = []
        cur = tip
        while cur != base:
            j = self.joint_to_child(cur)
            if j is None:
                return None
            out.append(j)
            cur = j.parent
        return out[::-1]

    def link_pose(self, link: str, q: dict[str, float] | None = None, memo: dict | None = None) -> np.ndarray:
        """4x4 pose of ``link`` in the root link frame for joint positions ``q`` (missing → 0;
        mimic followers follow their leader).

        ``memo``: a dict the caller keeps across calls for one URDF (a sweep over gripper
        positions): the product over each chain prefix with the same joint values is computed
        once, by the same operations in the same order, so the poses are bit-for-bit the ones
        computed without it."""
        q = dict(q or {})
        T = np.eye(4)
        if memo is None:
            for j in self.chain(self.root, link) or []:
                T = T @ j.origin @ joint_motion(j, self.joint_value(j, q))
            return T
        chain = memo.get(link)
        if chain is None:
            chain = memo[link] = tuple(self.chain(self.root, link) or [])
        key: tuple = ()
        for j in chain:
            key += (j.name, self.joint_value(j, q))
            hit = memo.get(key)
            if hit is None:
                hit = memo[key] = T @ j.origin @ joint_motion(j, key[-1])
            T = hit
        return T.copy()

    def joint_value(self, j: Joint, q: dict[str, float]) -> float:
        if j.mimic is not None and j.name not in q:
            return j.mimic.multiplier * q.get(j.mimic.joint, 0.0) + j.mimic.offset
        return q.get(j.name, 0.0)

    def descendants(self, joint: str) -> set[str]:
        """Links moved by ``joint``."""
        start = self.joints[joint].child
        out, stack = {start}, [start]
        while stack:
            cur = stack.pop()
            for j in self.joints.values():
                if j.parent == cur and j.child not in out:
                    out.add(j.child)
                    stack.append(j.child)
        return out


FRAME_LINK_MASS = 0.001  # kg given to a link without <inertial> and without collision geometry (a frame)
SOLID_LINK_MASS = 0.01  # kg given to a link without <inertial> that has collision geometry (a pad, a bracket)


def missing_link_mass(link: Link) -> float:
    """Mass (kg) robocfg loads a link without ``<inertial>`` with, where PyBullet would use 1 kg:
    light enough not to load the arm or tilt a gripper, heavy enough for a stable solver."""
    return SOLID_LINK_MASS if link.collisions else FRAME_LINK_MASS


def joint_motion(j: Joint, value: float) -> np.ndarray:
    T = np.eye(4)
    if j.type in ("revolute", "continuous"):
        T[:3, :3] = axis_angle_matrix(j.axis, value)
    elif j.type == "prismatic":
        T[:3, 3] = j.axis * value
    return T
