"""Compose one URDF from a robot's URDF and its attachments (grippers, tools, cells), in order.

Each attachment's root link is welded to ``mount_link`` (a link of the composition so far) by a
fixed joint ``{name}_mount`` whose origin is ``mount_xyz`` (m) / ``mount_rpy`` (rad, URDF rpy) in
the ``mount_link`` frame. Names:

* with an explicit ``prefix``, every link and joint name of the attachment gets it;
* without, only names that already exist in the composition get ``{name}_`` (``name`` defaults to
  the attachment URDF's file stem), so the YAML can keep using the original names;
* references inside the attachment (parent/child, mimic, transmissions, ``drake:`` collision
  groups, gazebo ``reference``) follow the renames; clashing top-level materials are renamed too.

Mesh filenames are rewritten to absolute resolved paths, so the composed file can live anywhere:
it is written to the cache folder (:func:`cache_dir`), named by a hash of its content, never next
to the user's files. Pure XML (xml.etree): no simulator, fast enough for ``robocfg validate``.
"""

from __future__ import annotations

import hashlib
import math
import os
import re
import tempfile
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf_xml import read_urdf_xml
from robocfg.cachedir import cache_dir
from robocfg.suggest import did_you_mean

if TYPE_CHECKING:
    from robocfg.config.robot import Attachment

COMPOSER_VERSION = "1"
UNDECLARED_NS = "urn:robocfg:undeclared:"


@dataclass(frozen=True)
class Part:
    """One attachment to weld on: its resolved URDF file and where it goes."""

    urdf_path: Path
    mount_link: str
    mount_xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    mount_rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)  # rad, URDF rpy (R = Rz·Ry·Rx)
    name: str | None = None  # default: urdf_path stem
    prefix: str | None = None

    @property
    def label(self) -> str:
        return self.name or re.sub(r"[^A-Za-z0-9_\-]", "_", self.urdf_path.stem)

    @classmethod
    def of(cls, attachment: Attachment, urdf_path: Path) -> Part:
        """The part of a robot YAML's ``attachments`` entry whose URDF resolved to ``urdf_path``
        (mount angles converted from degrees)."""
        x, y, z = attachment.mount_xyz
        return cls(urdf_path, attachment.mount_link, (x, y, z), rpy_from_deg(attachment.mount_rpy_deg),
                   attachment.name, attachment.prefix)


@dataclass(frozen=True)
class CompositionProblem:
    """A problem in the inputs: ``index`` is the attachment (None: the base URDF); ``key`` the field."""

    index: int | None
    key: str
    message: str


class CompositionError(Exception):
    """The inputs cannot be composed; ``problems`` says where and why."""

    def __init__(self, problems: list[CompositionProblem]):
        self.problems = problems
        super().__init__("; ".join(p.message for p in problems))


@dataclass
class Composed:
    """The composed URDF file and, per attachment, the names that were changed (old → new)."""

    path: Path
    renamed: list[dict[str, str]] = field(default_factory=list)
    mount_joints: list[str] = field(default_factory=list)


def compose(base: Path, parts: Sequence[Part], resolver: Resolver, out_dir: Path | None = None) -> Composed:
    """Compose ``base`` with ``parts`` (in order) into one URDF in ``out_dir`` (default: the cache).

    Raises CompositionError listing every problem (unknown mount link with a suggestion, a part
    without a single root link, a mesh that does not resolve, names that still clash)."""
    problems: list[CompositionProblem] = []
    robot = _load(base, None, resolver, problems)
    if robot is None:
        raise CompositionError(problems)
    links = {el.get("name", "") for el in robot.findall("link")}
    joints = {el.get("name", "") for el in robot.findall("joint")}
    materials = {el.get("name", "") for el in robot.findall("material")}
    out = Composed(Path())
    for i, part in enumerate(parts):
        tree = _load(part.urdf_path, i, resolver, problems)
        renamed: dict[str, str] = {}
        out.renamed.append(renamed)
        if tree is None:
            continue
        if part.mount_link not in links:
            problems.append(CompositionProblem(i, "mount_link", f"no link {part.mount_link!r} to mount on"
                                               f"{did_you_mean(part.mount_link, sorted(links))}"))
            continue
        p_links = [el.get("name", "") for el in tree.findall("link")]
        p_joints = [el.get("name", "") for el in tree.findall("joint")]
        roots = [n for n in p_links if n not in {c.get("link") for c in tree.iter("child")}]
        if len(roots) != 1:
            problems.append(CompositionProblem(i, "urdf", f"{part.urdf_path} must have exactly one root link, found {roots or 'none'}"))
            continue
        lmap = _renames(p_links, links, part)
        jmap = _renames(p_joints, joints, part)
        mount = f"{part.label}_mount"
        clash = sorted((set(lmap.values()) & links) | (set(jmap.values()) & joints) | ({mount} & (joints | set(jmap.values()))))
        if clash:
            problems.append(CompositionProblem(i, "prefix" if part.prefix is not None else "name",
                                               f"names still clash after prefixing: {clash}; choose another prefix/name"))
            continue
        mmap = {m: f"{part.label}_{m}" for m in (el.get("name", "") for el in tree.findall("material")) if m and m in materials}
        _apply_renames(tree, lmap, jmap, mmap)
        robot.append(_mount_joint(mount, part, lmap[roots[0]]))
        for el in list(tree):
            robot.append(el)
        links |= set(lmap.values())
        joints |= set(jmap.values()) | {mount}
        materials |= {el.get("name", "") for el in tree.findall("material")}
        renamed.update({k: v for k, v in {**lmap, **jmap, **mmap}.items() if k != v})
        out.mount_joints.append(mount)
    if problems:
        raise CompositionError(problems)
    text = _serialise(robot)
    digest = hashlib.sha256((COMPOSER_VERSION + text).encode()).hexdigest()[:16]
    stem = "+".join([base.stem, *(p.label for p in parts)])[:80]
    out.path = _write(out_dir or cache_dir() / "urdf", f"{stem}_{digest}.urdf", text)
    return out


def _load(path: Path, index: int | None, resolver: Resolver, problems: list[CompositionProblem]) -> ET.Element | None:
    """Parse a URDF and make its mesh filenames absolute; None (problems appended) on failure."""
    try:
        root = read_urdf_xml(path)
    except (ET.ParseError, OSError) as exc:
        problems.append(CompositionProblem(index, "urdf", f"URDF {path} does not parse: {exc}"))
        return None
    if root.tag != "robot":
        problems.append(CompositionProblem(index, "urdf", f"URDF {path}: top element is <{root.tag}>, expected <robot>"))
        return None
    for link in root.findall("link"):
        for mesh in link.iter("mesh"):
            fn = mesh.get("filename", "")
            try:
                mesh.set("filename", str(resolver.mesh(fn, path)))
            except UnresolvedPath as exc:
                tried = ", ".join(str(t) for t in exc.tried)
                problems.append(CompositionProblem(index, "urdf", f"mesh {fn!r} of link {link.get('name')!r} in {path} not found; tried: {tried}"))
    return root


def _renames(names: list[str], taken: set[str], part: Part) -> dict[str, str]:
    if part.prefix is not None:
        return {n: part.prefix + n for n in names}
    return {n: (f"{part.label}_{n}" if n in taken else n) for n in names}


def _local(tag: object) -> str:
    return tag.rsplit("}", 1)[-1] if isinstance(tag, str) else ""


def _apply_renames(root: ET.Element, lmap: dict[str, str], jmap: dict[str, str], mmap: dict[str, str]) -> None:
    """Rename link/joint/material definitions and every reference to them."""
    for el in root.iter():
        tag = _local(el.tag)
        for attr, value in list(el.attrib.items()):
            key = _local(attr)
            if key == "name" and tag in ("link", "joint", "material"):
                new = {"link": lmap, "joint": jmap, "material": mmap}[tag].get(value, value)
            elif key == "link":
                new = lmap.get(value, value)
            elif key == "joint":
                new = jmap.get(value, value)
            elif key == "reference":
                new = lmap.get(value, jmap.get(value, value))
            else:
                continue
            el.set(attr, new)


def _mount_joint(name: str, part: Part, child: str) -> ET.Element:
    j = ET.Element("joint", name=name, type="fixed")
    ET.SubElement(j, "origin", xyz=" ".join(repr(float(v)) for v in part.mount_xyz),
                  rpy=" ".join(repr(float(v)) for v in part.mount_rpy))
    ET.SubElement(j, "parent", link=part.mount_link)
    ET.SubElement(j, "child", link=child)
    return j


def _serialise(root: ET.Element) -> str:
    """XML text; prefixes that were used undeclared (``drake:``) keep their name."""
    for el in root.iter():
        for name in (el.tag, *el.attrib):
            if isinstance(name, str) and name.startswith("{" + UNDECLARED_NS):
                prefix = name[len(UNDECLARED_NS) + 1 :].split("}", 1)[0]
                ET.register_namespace(prefix, UNDECLARED_NS + prefix)
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n<!-- composed by robocfg; do not edit (regenerated from the robot YAML) -->\n' + \
        ET.tostring(root, encoding="unicode") + "\n"


def _write(folder: Path, filename: str, text: str) -> Path:
    """Write ``text`` atomically unless the same file exists; falls back to the temp folder."""
    for d in (folder, Path(tempfile.gettempdir()) / f"robocfg-cache-{os.getuid() if hasattr(os, 'getuid') else 0}"):
        target = d / filename
        try:
            if target.is_file() and target.read_text() == text:
                return target
            d.mkdir(parents=True, exist_ok=True)
            tmp = target.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_text(text)
            tmp.replace(target)
            return target
        except OSError:
            continue
    raise OSError(f"cannot write the composed URDF to {folder} or the temp folder")


def rpy_from_deg(rpy_deg: Sequence[float]) -> tuple[float, float, float]:
    r, p, y = (math.radians(v) for v in rpy_deg)
    return (r, p, y)
