"""Draft a robot YAML from a URDF (what ``robocfg new-robot`` writes).

Everything is derived from the URDF's structure and geometry, never from names:

* **arm** — the longest serial chain of non-mimic movable joints (:func:`longest_serial_chain`),
  less a one-jaw gripper's jaw at its end; ``base_link`` is the parent link of its first joint;
* **gripper, ee_axis, tcp_offset, fingers** — :mod:`robocfg.assets.draft_gripper` (parallel,
  one-jaw, or the tip of a tool), measured exactly as ``robocfg validate`` measures them;
* **ee_link** — among the links rigidly attached to the last arm joint (:func:`ee_candidates`),
  the one the gripper hangs from (else the deepest one);
* **R_ee_graspnet** — rows are the grasp axes in the ``ee_link`` frame: x = approach
  (``+ee_axis``), y = the ee axis of the finger closing direction, z = x × y;
* **home** — here 0 where 0 is well inside a joint's limits (10 % of the range), else
  mid-limits; the CLI then replaces it by an IK pose with the tool pointing down over the
  workspace (``robocfg.kinematics.home``), which needs the drafted file to load;
* **link_masses** — every link without ``<inertial>`` (PyBullet would load it as 1 kg).

A composed robot (``urdf`` + ``attachments``) is drafted from its composed URDF and written with
its own ``urdf`` and ``attachments``. Frames: geometry in the ``ee_link`` frame, metres. No
printing here: the CLI reports the notes.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.assets.draft_gripper import (
    GripperDraft,
    GripperGeometry,
    UnsupportedGripper,
    one_jaw_gripper,
    parallel_gripper,
    tool_tip,
)
from robocfg.assets.inspection import ee_candidates, longest_serial_chain
from robocfg.assets.paths import Resolver, _package_root
from robocfg.assets.urdf import Urdf, missing_link_mass
from robocfg.config.robot import RobotSource

HOME_MARGIN = 0.1  # fraction of a joint's range: 0 closer than this to a limit is not used as home
AXES = "xyz"
URI_ROOTS = (("pybullet_data://", "pybullet_data"), ("airo_models://", "airo_models"))


@dataclass
class AttachmentDraft:
    """An attachment copied into the draft (``urdf`` already relative to the output folder)."""

    urdf: str
    mount_link: str
    mount_xyz: list[float]
    mount_rpy_deg: list[float]
    name: str | None = None
    prefix: str | None = None


@dataclass
class RobotDraft:
    """Everything ``new-robot`` derives, plus ``notes``: what a person must check."""

    name: str
    urdf_uri: str
    arm_joints: list[str]
    base_link: str
    ee_link: str
    ee_candidates: list[str]
    ee_axis: str
    tcp_offset: float
    R_ee_graspnet: list[list[float]]
    home: list[float]
    gripper: GripperDraft | None
    link_masses: dict[str, float] = field(default_factory=dict)  # links without <inertial> → kg
    notes: list[str] = field(default_factory=list)
    attachments: list[AttachmentDraft] = field(default_factory=list)
    package_dirs: dict[str, str] = field(default_factory=dict)
    suction_link: str | None = None  # the tool link whose tip is the TCP, when there is no gripper
    home_found: bool = False  # True once the home comes from IK (tool down over the workspace)


def draft_robot(urdf: Urdf, name: str, out_dir: Path, urdf_uri: str | None = None) -> RobotDraft:
    """Derive a robot draft from a parsed URDF; ``out_dir`` is where the YAML will live (for the
    relative URDF path). ``urdf_uri`` overrides the URDF reference written (a composed robot
    refers to its own ``urdf`` and ``attachments``, not the composed file)."""
    notes: list[str] = []
    chain = longest_serial_chain(urdf)
    if not chain:
        raise ValueError(f"{urdf.path}: no movable joints, nothing to drive")
    resolver = Resolver(urdf.path.parent)
    found: GripperGeometry | None = None
    jaw_parent: str | None = None
    if len(chain) > 1:  # a jaw at the end of the serial chain (one-jaw gripper) is not an arm joint
        found = one_jaw_gripper(urdf, resolver, chain, urdf.joints[chain[-1]].parent)
        if found is not None and found.gripper is not None:
            fingers = found.gripper.finger_links
            notes.append(f"one-jaw gripper: {chain[-1]!r} moves {fingers[0]!r} against the fixed jaw {fingers[1]!r}")
            jaw_parent = urdf.joints[chain[-1]].parent
            chain = chain[:-1]
    base_link = urdf.joints[chain[0]].parent
    cands = ee_candidates(urdf, chain)
    below = urdf.descendants(chain[-1])
    leaders = [j.name for j in urdf.joints.values()
               if j.movable and j.mimic is None and j.name not in chain and j.parent in below]
    ee_link = jaw_parent or _pick_ee_link(urdf, cands, leaders)
    suction_link = None
    if found is None and leaders:
        try:
            found = parallel_gripper(urdf, resolver, ee_link, leaders)
        except UnsupportedGripper as exc:
            notes.append(f"unsupported gripper: {exc}; write the gripper block by hand (type parallel, one_jaw or suction)")
    if found is None:
        tip = tool_tip(urdf, resolver, cands)
        if not leaders:
            notes.append("no gripper joints below the arm: for a suction tool add `gripper: {type: suction, link: ...}` "
                         "(the draft names the tool link in a comment); tcp_offset is the tip of the tool's geometry "
                         "(a suction cup's face)")
        if tip is not None:
            found, ee_link, suction_link = tip
        else:
            found = GripperGeometry(None, "z", 0.1)
            notes.append("no tool geometry: ee_axis z and tcp_offset 0.1 are placeholders")
    gripper, ee_axis, tcp = found.gripper, found.ee_axis, found.tcp_offset
    if tcp <= 0:
        notes.append(f"the tool lies on the negative side of every axis of {ee_link!r}: pick an ee_link whose "
                     "+x, +y or +z points at the fingertips")
        tcp = 0.1
    if gripper is not None:
        notes.append(f"gripper max_force {gripper.max_force:g} presses each pad with about 20 N (the lever from "
                     f"{gripper.joints} to the pads; capped by the URDF effort): check it against the object's weight")
        notes.append(f"tcp_offset {tcp:.4f} m is the finger-pad midpoint with the gripper closed (as validate measures it); "
                     "grasp a test object and adjust")
    closing_sign = gripper.closing_sign if gripper else 1.0
    R = _r_ee_graspnet(ee_axis, gripper.closing_axis if gripper else _other_axis(ee_axis), closing_sign)
    home = []
    for jn in chain:
        j = urdf.joints[jn]
        lo, hi = (j.lower, j.upper) if j.type != "continuous" else (-math.pi, math.pi)
        margin = HOME_MARGIN * (hi - lo)
        home.append(0.0 if lo + margin <= 0.0 <= hi - margin else round((lo + hi) / 2, 4))
    notes.append("drives (stiffness, damping, max_force) are defaults for a small arm — raise max_force for a heavy one")
    if len(cands) > 1:
        notes.append(f"ee_link {ee_link!r} chosen among {cands}")
    masses = {j.child: missing_link_mass(urdf.links[j.child]) for j in urdf.joints.values()
              if j.child in urdf.links and urdf.links[j.child].mass is None}
    if masses:
        notes.append(f"links without <inertial> get small masses in physics.link_masses (0.01 kg with geometry, "
                     f"0.001 kg for frames): {sorted(masses)}")
    return RobotDraft(name, urdf_uri or _uri(urdf.path, out_dir), chain, base_link, ee_link, cands, ee_axis, round(tcp, 4), R,
                      home, gripper, masses, notes, suction_link=suction_link)


def draft_composed(source: Path, src: RobotSource, name: str, out_dir: Path) -> RobotDraft:
    """Draft a robot given as ``urdf`` + ``attachments`` (a ``RobotSource`` read from ``source``):
    the geometry comes from the composed URDF, the draft keeps the parts (paths rebased on
    ``out_dir``). Raises UnresolvedPath or CompositionError for missing or clashing parts."""
    from robocfg.assets.compose import Part, compose
    from robocfg.assets.urdf_xml import parse_urdf

    resolver = Resolver(source.parent, src.package_dirs)
    base = resolver.urdf(src.urdf)
    parts = [Part.of(a, resolver.urdf(a.urdf)) for a in src.attachments]
    composed = compose(base, parts, resolver).path
    d = draft_robot(parse_urdf(composed), name, out_dir, urdf_uri=_rebase(src.urdf, source.parent, out_dir))
    d.attachments = [AttachmentDraft(_rebase(a.urdf, source.parent, out_dir), a.mount_link, list(a.mount_xyz),
                                     list(a.mount_rpy_deg), a.name, a.prefix) for a in src.attachments]
    d.package_dirs = {k: _rebase(v, source.parent, out_dir) for k, v in src.package_dirs.items()}
    return d


def _rebase(ref: str, src_dir: Path, out_dir: Path) -> str:
    """A path written relative to ``src_dir``, rewritten relative to ``out_dir`` (URIs unchanged)."""
    if "://" in ref or Path(ref).is_absolute():
        return ref
    return Path(os.path.relpath((src_dir / ref).resolve(), out_dir.resolve())).as_posix()


def _pick_ee_link(urdf: Urdf, cands: list[str], leaders: list[str]) -> str:
    """The candidate the gripper joints hang from, else the deepest candidate."""
    parents = [urdf.joints[j].parent for j in leaders]
    for link in reversed(cands):
        if link in parents:
            return link
    return max(cands, key=lambda ln: len(urdf.chain(urdf.root, ln) or []))


def _other_axis(axis: str) -> str:
    return "y" if axis != "y" else "z"


def _r_ee_graspnet(ee_axis: str, closing: str, sign: float = 1.0) -> list[list[float]]:
    """Rows: grasp x (approach = +ee_axis), y (closing = sign · closing axis), z = x × y, in ee coordinates."""
    x = np.eye(3)[AXES.index(ee_axis)]
    y = sign * np.eye(3)[AXES.index(closing)]
    R = np.vstack([x, y, np.cross(x, y)])
    return [[float(v) + 0.0 for v in row] for row in R]


def _uri(urdf_path: Path, out_dir: Path) -> str:
    """``pybullet_data://`` / ``airo_models://`` when the URDF lives there, else a path relative to ``out_dir``."""
    p = urdf_path.resolve()
    for prefix, module in URI_ROOTS:
        root = _package_root(module)
        if root is not None and p.is_relative_to(root.resolve()):
            return prefix + p.relative_to(root.resolve()).as_posix()
    return Path(os.path.relpath(p, out_dir.resolve())).as_posix()
