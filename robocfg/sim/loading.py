"""Loading a robot URDF into PyBullet: path rewriting, link masses, mesh failures named.

* Mesh ``package://`` URIs are resolved with the robot YAML's ``package_dirs`` (our Resolver) and a
  rewritten copy of the URDF with absolute mesh paths is loaded (cached in the temp folder).
* ``physics.link_masses`` become ``<inertial>`` blocks in that copy (inertia of a 2 cm cube of that
  mass); every other link without ``<inertial>`` (the root excepted) gets a small one too —
  ``missing_link_mass``: 0.01 kg with collision geometry, 0.001 kg for a bare frame — where
  PyBullet would load it as 1 kg (``robocfg validate`` warns about each such link).
* Markedly concave collision meshes of one-jaw gripper jaws are replaced by their convex decomposition
  (``robocfg.sim.concave``; PyBullet collides with a mesh's convex hull).
* PyBullet's C-level messages are captured; a mesh PyBullet cannot read (it then silently loads the
  link with no collision shape) or cannot find raises ConfigError naming the mesh.
* With self collision on, the links a parallel gripper's joints move do not collide with each
  other (:func:`filter_gripper_linkage`).
"""

from __future__ import annotations

import copy
import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import TYPE_CHECKING

import pybullet as p

from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf import FRAME_LINK_MASS, missing_link_mass
from robocfg.assets.urdf_xml import read_urdf_xml
from robocfg.checks.robot import CheckedRobot
from robocfg.config.robot import ParallelGripperConfig
from robocfg.errors import ConfigError
from robocfg.sim.quiet import captured_stdout

if TYPE_CHECKING:
    from robocfg.sim.robot import RobotHandle

SMALL_LINK_SIZE = 0.02  # m: cube edge used for the inertia of link_masses entries


def prepared_urdf(robot: CheckedRobot) -> Path:
    """The URDF file to hand to PyBullet: the original, or a rewritten copy when needed."""
    cfg = robot.config
    root = read_urdf_xml(robot.urdf_path)
    resolver = Resolver(robot.path.parent, cfg.package_dirs)
    changed = False
    for mesh in root.iter("mesh"):
        fn = mesh.get("filename", "")
        if fn.startswith(("package://", "file://")) or not Path(fn).is_absolute():
            try:
                resolved = resolver.mesh(fn, robot.urdf_path)
            except UnresolvedPath:
                continue  # robocfg validate reports it; PyBullet will name it too
            if fn != str(resolved):
                mesh.set("filename", str(resolved))
                changed = True
    changed |= _split_multi_material_visuals(root)
    changed |= _decompose_finger_meshes(root, robot)
    children = {c.get("link") for j in root.findall("joint") for c in j.findall("child")}
    for link in root.findall("link"):
        name = link.get("name", "")
        mass = cfg.physics.link_masses.get(name)
        if mass is None and name in children and _massless(link):  # the root link is left alone
            mass = missing_link_mass(robot.urdf.links[name]) if name in robot.urdf.links else FRAME_LINK_MASS
        if mass is None:
            continue
        inertial = link.find("inertial")
        if inertial is not None:
            link.remove(inertial)
        i = mass * SMALL_LINK_SIZE**2 / 6
        inertial = ET.SubElement(link, "inertial")
        ET.SubElement(inertial, "mass", value=repr(mass))
        ET.SubElement(inertial, "inertia", ixx=repr(i), iyy=repr(i), izz=repr(i), ixy="0", ixz="0", iyz="0")
        changed = True
    if not changed:
        return robot.urdf_path
    text = ET.tostring(root, encoding="unicode")
    digest = hashlib.sha1((str(robot.urdf_path) + text).encode()).hexdigest()[:12]
    out = Path(tempfile.gettempdir()) / "robocfg_urdf" / f"{robot.urdf_path.stem}_{digest}.urdf"
    if not out.exists():
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text)
        tmp.replace(out)
    return out


def _decompose_finger_meshes(root: ET.Element, robot: CheckedRobot) -> bool:
    """Point the collision meshes of one-jaw finger links that are markedly concave at their convex
    decomposition (``robocfg.sim.concave``): PyBullet would collide with one hull filling the
    space between the jaws."""
    from robocfg.config.robot import OneJawGripperConfig

    # One-jaw grippers only: their fixed jaw is typically part of the hand's mesh. Two-finger
    # grippers keep PyBullet's hulls (their physics, and the shipped robots' figures, unchanged).
    fingers = {f for arm in robot.config.arms if isinstance(arm.gripper, OneJawGripperConfig)
               for f in arm.gripper.finger_links}
    if not fingers:
        return False
    from robocfg.sim.concave import convex_parts  # imported for one-jaw grippers only

    changed = False
    for link in root.findall("link"):
        if link.get("name") not in fingers:
            continue
        for mesh in link.findall("collision/geometry/mesh"):
            fn = Path(mesh.get("filename", ""))
            if not fn.is_absolute() or not fn.is_file():
                continue
            v = [float(x) for x in (mesh.get("scale") or "1 1 1").split()]
            parts = convex_parts(fn, (v[0], v[1], v[2]) if len(v) == 3 else (1.0, 1.0, 1.0))
            if parts is not None:
                mesh.set("filename", str(parts))
                changed = True
    return changed


def _massless(link: ET.Element) -> bool:
    """No ``<inertial>`` mass (PyBullet would load the link as 1 kg)."""
    return link.find("inertial/mass") is None


def _split_multi_material_visuals(root: ET.Element) -> bool:
    """Replace each uncoloured multi-material OBJ visual by one coloured visual per material."""
    changed = False
    for link in root.findall("link"):
        for k, visual in enumerate(list(link.findall("visual"))):
            mesh = visual.find("geometry/mesh")
            if mesh is None or visual.find("material") is not None:
                continue
            fn = Path(mesh.get("filename", ""))
            if fn.suffix.lower() != ".obj" or not fn.is_absolute() or not fn.is_file():
                continue
            # imported for uncoloured OBJ visuals only
            from robocfg.sim.visuals import split_by_material

            parts = split_by_material(fn)
            if not parts:
                continue
            at = list(link).index(visual)
            link.remove(visual)
            for i, (path, rgba) in enumerate(parts):
                v = copy.deepcopy(visual)
                v.find("geometry/mesh").set("filename", str(path))  # type: ignore[union-attr]
                mat = ET.SubElement(v, "material", name=f"robocfg_{link.get('name', '')}_{k}_{i}")
                ET.SubElement(mat, "color", rgba=" ".join(f"{c:.4f}" for c in rgba))
                link.insert(at + i, v)
            changed = True
    return changed


def load_robot_urdf(client: int, robot: CheckedRobot, position, quat_xyzw, flags: int) -> int:
    """``loadURDF`` with fixed base per config; ConfigError naming the mesh when one cannot be loaded."""
    path = prepared_urdf(robot)
    with captured_stdout() as log:
        try:
            body = p.loadURDF(str(path), list(position), list(quat_xyzw), useFixedBase=robot.config.fixed_base,
                              flags=flags, physicsClientId=client)
        except p.error:
            body = -1
    if body < 0:
        raise ConfigError([robot.doc.problem(("urdf",), _failure(robot, log))])
    bad = _links_missing_collision(client, body, robot)
    if bad:
        p.removeBody(body, physicsClientId=client)
        raise ConfigError([robot.doc.problem(("urdf",), f"PyBullet cannot load mesh {fn!r} of link {ln!r} "
                                             f"(the link would have no collision shape){_hint(log, fn)}")
                           for ln, fn in bad])
    return body


def filter_gripper_linkage(client: int, robot: RobotHandle) -> None:
    """No self-collision among the links a parallel gripper's joints move (leaders and mimic
    followers), on the loaded ``robot`` of PyBullet client ``client``: PyBullet's convex hulls of
    linkage parts overlap at rest and would jam."""
    urdf = robot.checked.urdf
    for arm in robot.arms.values():
        g = arm.config.gripper
        if not isinstance(g, ParallelGripperConfig):
            continue
        leaders = robot.checked.gripper_joints(arm.config)
        joints = leaders + robot.checked.mimic_followers(leaders)
        moved = set().union(*(urdf.descendants(j) for j in joints))
        parents = {urdf.joints[j].parent for j in joints}
        links = sorted((moved | parents) & set(robot.link_index))
        for i, a in enumerate(links):
            for b in links[i + 1 :]:
                p.setCollisionFilterPair(robot.body_id, robot.body_id, robot.link(a), robot.link(b), 0,
                                         physicsClientId=client)


def _failure(robot: CheckedRobot, log: list[str]) -> str:
    meshes = [g.filename for link in robot.urdf.links.values() for g in (*link.visuals, *link.collisions)
              if g.kind == "mesh" and g.filename]
    named = [m for m in meshes if any(Path(m).name in line for line in log)]
    if named:
        return f"PyBullet cannot load {robot.urdf_path}: mesh {named[0]!r} failed{_hint(log, named[0])}"
    detail = "; ".join(line.strip() for line in log if "rror" in line or "cannot" in line)[:300]
    return f"PyBullet cannot load {robot.urdf_path}" + (f": {detail}" if detail else "")


def _hint(log: list[str], filename: str) -> str:
    name = Path(filename).name
    lines = [line.strip() for line in log if name in line and "b3" not in line]
    return f" — PyBullet says: {lines[0]}" if lines else ""


def _links_missing_collision(client: int, body: int, robot: CheckedRobot) -> list[tuple[str, str]]:
    index = {p.getBodyInfo(body, physicsClientId=client)[0].decode(): -1}
    for i in range(p.getNumJoints(body, physicsClientId=client)):
        index[p.getJointInfo(body, i, physicsClientId=client)[12].decode()] = i
    bad = []
    for link in robot.urdf.links.values():
        meshes = [g.filename for g in link.collisions if g.kind == "mesh" and g.filename]
        if meshes and link.name in index and not p.getCollisionShapeData(body, index[link.name], physicsClientId=client):
            bad.append((link.name, meshes[0]))
    return bad
