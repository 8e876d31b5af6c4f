"""A light URDF reader (xml.etree): links, joints, limits, mimic tags, geometry, inertials.

Fast enough for ``robocfg validate`` (no trimesh, no simulator). DOF indices follow the order of
movable joints in the file, the same order PyBullet uses for its joint indices.

Why not yourdfpy (used by the browser viewer) or pinocchio: a problem in a URDF is reported at
its line (``panda.urdf:42:``), which needs the XML parser's positions; yourdfpy imports trimesh
(seconds of start-up for ``validate``, see ``robocfg.assets.meshes``), and pinocchio belongs to
the kinematics layer above this one. ``Urdf.link_pose`` is the few lines of forward kinematics
the URDF checks need (finger pads, TCP) before any kinematic model exists.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from robocfg.geometry import axis_angle_matrix, rpy_matrix

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

    def link_pose(self, link: str, q: dict[str, float] | None = None) -> np.ndarray:
        """4x4 pose of ``link`` in the root link frame for joint positions ``q`` (missing → 0;
        mimic followers follow their leader)."""
        q = dict(q or {})
        T = np.eye(4)
        for j in self.chain(self.root, link) or []:
            T = T @ j.origin @ joint_motion(j, self.joint_value(j, q))
        return T

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


def _floats(text: str | None, n: int, default: float = 0.0) -> tuple[float, ...]:
    if not text:
        return (default,) * n
    vals = [float(v) for v in text.split()]
    if len(vals) != n:
        raise ValueError(f"expected {n} numbers, got {text!r}")
    return tuple(vals)


def _origin(el: ET.Element | None) -> np.ndarray:
    T = np.eye(4)
    if el is None:
        return T
    T[:3, 3] = _floats(el.get("xyz"), 3)
    T[:3, :3] = rpy_matrix(*_floats(el.get("rpy"), 3))
    return T


def _geometry(el: ET.Element) -> Geometry | None:
    g = el.find("geometry")
    if g is None or len(g) == 0:
        return None
    shape = g[0]
    origin = _origin(el.find("origin"))
    if shape.tag == "mesh":
        scale = _floats(shape.get("scale"), 3, 1.0) if shape.get("scale") else (1.0, 1.0, 1.0)
        return Geometry("mesh", origin, filename=shape.get("filename", ""), scale=scale)  # type: ignore[arg-type]
    if shape.tag == "box":
        return Geometry("box", origin, size=_floats(shape.get("size"), 3))
    if shape.tag == "sphere":
        return Geometry("sphere", origin, size=(float(shape.get("radius", 0)),))
    if shape.tag in ("cylinder", "capsule"):
        return Geometry(shape.tag, origin, size=(float(shape.get("radius", 0)), float(shape.get("length", 0))))
    return None


def read_urdf_xml(path: Path | str) -> ET.Element:
    """The URDF's root element. Namespace prefixes used without a declaration (airo-models'
    UR URDFs write ``drake:acceleration``; urdfdom, PyBullet and pinocchio accept it) are declared
    before parsing. Raises ET.ParseError / OSError."""
    import re

    data = Path(path).read_bytes()
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        if "unbound prefix" not in str(exc):
            raise
        found = re.findall(rb"(?:[\s<]|</)([A-Za-z_][\w.-]*):[A-Za-z_]", data)
        prefixes = sorted({p.decode() for p in found} - {"xmlns", "xml"})
        decl = "".join(f' xmlns:{px}="urn:robocfg:undeclared:{px}"' for px in prefixes).encode()
        return ET.fromstring(re.sub(rb"<robot\b", b"<robot" + decl, data, count=1))


_NUMERIC_ATTRS = frozenset({"xyz", "rpy", "lower", "upper", "effort", "velocity", "value", "size", "radius",
                            "length", "scale", "multiplier", "offset", "damping", "friction",
                            "ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
_NON_FINITE = re.compile(rb"(?i)nan|inf")


def _check_finite(path: Path) -> None:
    """UrdfParseError at the line of the first numeric attribute holding ``nan`` or ``inf``: such
    an origin, limit or inertia poisons every transform, and PyBullet/pinocchio fail far from the cause."""
    import xml.parsers.expat

    data = Path(path).read_bytes()
    if not _NON_FINITE.search(data):
        return  # the common case: no candidate token at all, no second parse
    parser = xml.parsers.expat.ParserCreate()
    found: list[tuple[int, str]] = []

    def start(tag: str, attrs: dict[str, str]) -> None:
        for key, text in attrs.items():
            if found or key not in _NUMERIC_ATTRS:
                continue
            for token in text.split():
                try:
                    bad = not np.isfinite(float(token))
                except ValueError:
                    bad = False  # not a number at all: reported by the parse itself
                if bad:
                    found.append((parser.CurrentLineNumber, f'<{tag} {key}="{text}">: {token!r} is not a finite number'))
                    return

    parser.StartElementHandler = start
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError:
        return  # prefixes the reader declares itself; the values it reads are checked when used
    if found:
        raise UrdfParseError(found[0][1], found[0][0])


def parse_urdf(path: Path) -> Urdf:
    """Parse a URDF file. Raises UrdfParseError with a line number when the XML is broken."""
    try:
        root = read_urdf_xml(path)
    except ET.ParseError as exc:
        raise UrdfParseError(f"broken XML: {exc}", exc.position[0] if exc.position else None) from None
    except OSError as exc:
        raise UrdfParseError(f"cannot read: {exc}") from None
    if root.tag != "robot":
        raise UrdfParseError(f"top element is <{root.tag}>, expected <robot>", 1)
    _check_finite(path)
    try:
        links: dict[str, Link] = {}
        for el in root.findall("link"):
            inertial = el.find("inertial")
            mass = None
            if inertial is not None and inertial.find("mass") is not None:
                mass = float(inertial.find("mass").get("value", 0))  # type: ignore[union-attr]
            vis = tuple(g for g in (_geometry(v) for v in el.findall("visual")) if g)
            col = tuple(g for g in (_geometry(c) for c in el.findall("collision")) if g)
            links[el.get("name", "")] = Link(el.get("name", ""), mass, vis, col)
        joints: dict[str, Joint] = {}
        for i, el in enumerate(root.findall("joint")):
            jtype = el.get("type", "fixed")
            limit = el.find("limit")
            lower = float(limit.get("lower", 0)) if limit is not None else 0.0
            upper = float(limit.get("upper", 0)) if limit is not None else 0.0
            if jtype == "continuous":
                lower, upper = -np.pi, np.pi
            mimic_el = el.find("mimic")
            mimic = None
            if mimic_el is not None:
                mimic = Mimic(mimic_el.get("joint", ""), float(mimic_el.get("multiplier", 1)), float(mimic_el.get("offset", 0)))
            axis_el = el.find("axis")
            axis = np.array(_floats(axis_el.get("xyz") if axis_el is not None else None, 3)) if axis_el is not None else np.array([1.0, 0, 0])
            if jtype in MOVABLE and np.linalg.norm(axis) > 0:
                axis = axis / np.linalg.norm(axis)
            parent, child, dyn = el.find("parent"), el.find("child"), el.find("dynamics")
            joints[el.get("name", "")] = Joint(
                name=el.get("name", ""),
                type=jtype,
                parent=parent.get("link", "") if parent is not None else "",
                child=child.get("link", "") if child is not None else "",
                origin=_origin(el.find("origin")),
                axis=axis,
                lower=lower,
                upper=upper,
                effort=float(limit.get("effort", 0)) if limit is not None else 0.0,
                velocity=float(limit.get("velocity", 0)) if limit is not None else 0.0,
                mimic=mimic,
                urdf_index=i,
                damping=float(dyn.get("damping", 0)) if dyn is not None else 0.0,
                friction=float(dyn.get("friction", 0)) if dyn is not None else 0.0,
            )
    except (ValueError, TypeError) as exc:
        raise UrdfParseError(f"bad value: {exc}") from None
    children = {j.child for j in joints.values()}
    roots = [n for n in links if n not in children]
    if len(roots) != 1:
        raise UrdfParseError(f"expected one root link, found {roots or 'none'}")
    order = _depth_first(roots[0], list(joints.values()))
    joints = {j.name: replace(j, urdf_index=i) for i, j in enumerate(order)}
    dof = [j.name for j in order if j.movable]
    return Urdf(path, root.get("name", ""), links, joints, roots[0], dof)


def _depth_first(root: str, joints: list[Joint]) -> list[Joint]:
    """Joints in PyBullet's index order: depth-first from the root, children in file order."""
    out: list[Joint] = []

    def visit(link: str) -> None:
        for j in joints:
            if j.parent == link:
                out.append(j)
                visit(j.child)

    visit(root)
    return out
