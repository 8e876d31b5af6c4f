"""Reading a URDF file (xml.etree) into the :class:`~robocfg.assets.urdf.Urdf` model: links with
their inertial mass and visual/collision geometry, joints with origin, axis (unit), limits,
dynamics and mimic tags, in PyBullet's joint order (depth first from the root link). Problems are
:class:`~robocfg.assets.urdf.UrdfParseError` with the XML line where it is known (broken XML, a
``nan``/``inf`` in a numeric attribute). Lengths in m, angles in rad.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np

from robocfg.assets.urdf import MOVABLE, Geometry, Joint, Link, Mimic, Urdf, UrdfParseError
from robocfg.geometry import rpy_matrix


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
        sx, sy, sz = _floats(shape.get("scale"), 3, 1.0)
        return Geometry("mesh", origin, filename=shape.get("filename", ""), scale=(sx, sy, sz))
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
            mass_el = None if inertial is None else inertial.find("mass")
            mass = None if mass_el is None else float(mass_el.get("value", 0))
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


def revolute_continuous(root: ET.Element, limit: float) -> set[str]:
    """Turn the continuous joints of the URDF ``root`` into revolute ones limited to
    [-``limit``, ``limit``] (rad), in place (a ``<limit>`` without effort or velocity is added
    where there is none). Returns the names of the converted joints."""
    converted: set[str] = set()
    for j in root.iter("joint"):
        if j.get("type") != "continuous":
            continue
        j.set("type", "revolute")
        lim = j.find("limit")
        if lim is None:
            lim = ET.SubElement(j, "limit", effort="0", velocity="0")
        lim.set("lower", repr(-limit))
        lim.set("upper", repr(limit))
        converted.add(j.get("name", ""))
    return converted
