"""Draft a robot YAML from a URDF (what ``robocfg new-robot`` writes).

Everything is derived from the URDF's structure and geometry, never from names:

* **arm** — the longest serial chain of non-mimic movable joints (:func:`longest_serial_chain`);
  ``base_link`` is the parent link of its first joint;
* **gripper** — the non-mimic movable joints below the arm (leaders); their ``<mimic>`` followers
  are left to the URDF; ``open``/``closed`` are the leader limits with the wider/narrower gap;
* **ee_link** — among the links rigidly attached to the last arm joint (:func:`ee_candidates`),
  the one the gripper hangs from (else the deepest one);
* **fingers** — of the leaf links the gripper joints move, the one reaching furthest along the
  approach axis and the furthest-reaching one on the other side of it;
* **ee_axis / tcp_offset** — the ``ee_link`` axis pointing at the finger-pad midpoint (gripper
  open) and the distance along it, measured exactly as ``robocfg validate`` measures it (the
  distal ``PAD_LENGTH`` of each finger's geometry);
* **R_ee_graspnet** — rows are the grasp axes in the ``ee_link`` frame: x = approach
  (``+ee_axis``), y = the ``+`` ee axis closest to the pad-to-pad line (finger closing axis),
  z = x × y;
* **home** — 0 where 0 is well inside a joint's limits (10 % of the range), else mid-limits.

Frames: all geometry in the ``ee_link`` frame, metres. No printing here: the CLI reports the notes.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.assets.inspection import ee_candidates, longest_serial_chain
from robocfg.assets.meshes import geometry_points
from robocfg.assets.paths import Resolver, UnresolvedPath, _package_root
from robocfg.assets.urdf import Urdf

PAD_LENGTH = 0.02  # m: the distal part of a finger counted as its pad (as robocfg validate does)
HOME_MARGIN = 0.1  # fraction of a joint's range: 0 closer than this to a limit is not used as home
MIN_FINGER_SEPARATION = 0.005  # m: two pads closer than this across the approach axis are one side
AXES = "xyz"
URI_ROOTS = (("pybullet_data://", "pybullet_data"), ("airo_models://", "airo_models"))


@dataclass
class GripperDraft:
    """A parallel gripper found in the URDF (leader joints and the finger geometry)."""

    joints: list[str]
    open: list[float]
    closed: list[float]
    finger_links: list[str]
    max_width: float  # m, pad-face gap when open
    min_width: float  # m, pad-face gap when closed
    max_force: float
    closing_axis: str  # +ee axis closest to the pad-to-pad line


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
    massless: list[str] = field(default_factory=list)  # moving links without <inertial>
    notes: list[str] = field(default_factory=list)


def draft_robot(urdf: Urdf, name: str, out_dir: Path) -> RobotDraft:
    """Derive a robot draft from a parsed URDF; ``out_dir`` is where the YAML will live (for the
    relative URDF path)."""
    notes: list[str] = []
    chain = longest_serial_chain(urdf)
    if not chain:
        raise ValueError(f"{urdf.path}: no movable joints, nothing to drive")
    base_link = urdf.joints[chain[0]].parent
    cands = ee_candidates(urdf, chain)
    below = urdf.descendants(chain[-1])
    leaders = [j.name for j in urdf.joints.values()
               if j.movable and j.mimic is None and j.name not in chain and j.parent in below]
    resolver = Resolver(urdf.path.parent)
    ee_link = _pick_ee_link(urdf, cands, leaders)
    gripper, ee_axis, tcp = None, "z", 0.1
    if leaders:
        found = _gripper(urdf, resolver, ee_link, leaders, notes)
        if found is not None:
            gripper, ee_axis, tcp = found
    else:
        notes.append("no gripper joints below the arm: add a `gripper:` block (suction: `type: suction` with the cup "
                     "link) and set ee_axis/tcp_offset to the tool's working point")
    R = _r_ee_graspnet(ee_axis, gripper.closing_axis if gripper else _other_axis(ee_axis))
    home = []
    for jn in chain:
        j = urdf.joints[jn]
        lo, hi = (j.lower, j.upper) if j.type != "continuous" else (-math.pi, math.pi)
        margin = HOME_MARGIN * (hi - lo)
        home.append(0.0 if lo + margin <= 0.0 <= hi - margin else round((lo + hi) / 2, 4))
    notes.append("home: 0 or mid-limits per joint — pick a pose that is clear of the table with the tool pointing down")
    notes.append("drives (stiffness, damping, max_force) are defaults for a small arm — raise max_force for a heavy one")
    if len(cands) > 1:
        notes.append(f"ee_link {ee_link!r} chosen among {cands}")
    massless = sorted({j.child for j in urdf.joints.values() if j.movable}
                      - {ln.name for ln in urdf.links.values() if ln.mass is not None and ln.mass > 0})
    if massless:
        notes.append(f"moving links without <inertial> get 0.01 kg in physics.link_masses: {massless}")
    return RobotDraft(name, _uri(urdf.path, out_dir), chain, base_link, ee_link, cands, ee_axis, round(tcp, 4), R,
                      home, gripper, massless, notes)


def _pick_ee_link(urdf: Urdf, cands: list[str], leaders: list[str]) -> str:
    """The candidate the gripper joints hang from, else the deepest candidate."""
    parents = [urdf.joints[j].parent for j in leaders]
    for link in reversed(cands):
        if link in parents:
            return link
    return max(cands, key=lambda ln: len(urdf.chain(urdf.root, ln) or []))


def _finger_pad(urdf: Urdf, resolver: Resolver, link: str, T_ee_inv: np.ndarray, q: dict[str, float]) -> np.ndarray | None:
    """(N, 3) geometry points of ``link`` in the ee_link frame, or None without geometry."""
    geoms = urdf.links[link].collisions or urdf.links[link].visuals
    pts = []
    for g in geoms:
        mesh = None
        if g.kind == "mesh":
            try:
                mesh = resolver.mesh(g.filename or "", urdf.path)
            except UnresolvedPath:
                continue
        pts.append(geometry_points(g, mesh))
    if not pts or not len(np.concatenate(pts)):
        return None
    T = T_ee_inv @ urdf.link_pose(link, q)
    return np.concatenate(pts) @ T[:3, :3].T + T[:3, 3]


def _pad_center(P: np.ndarray, axis: int) -> np.ndarray:
    tip = P[:, axis].max()
    pad = P[P[:, axis] >= tip - PAD_LENGTH]
    return (pad.min(axis=0) + pad.max(axis=0)) / 2


def _gripper(urdf: Urdf, resolver: Resolver, ee_link: str, leaders: list[str],
             notes: list[str]) -> tuple[GripperDraft, str, float] | None:
    followers = [j.name for j in urdf.joints.values() if j.mimic is not None and j.mimic.joint in leaders]
    moved = set().union(*(urdf.descendants(j) for j in leaders + followers))
    leaves = sorted(ln for ln in moved if not any(j.parent == ln for j in urdf.joints.values()))
    lo = {j: urdf.joints[j].lower for j in leaders}
    hi = {j: urdf.joints[j].upper for j in leaders}

    def clouds(q: dict[str, float]) -> dict[str, np.ndarray]:
        T_inv = np.linalg.inv(urdf.link_pose(ee_link, q))
        out = {}
        for ln in leaves:
            P = _finger_pad(urdf, resolver, ln, T_inv, q)
            if P is not None:
                out[ln] = P
        return out

    c_lo, c_hi = clouds(lo), clouds(hi)
    if len(c_lo) < 2:
        notes.append(f"gripper joints {leaders} move fewer than two links with geometry: fill in the gripper block by hand")
        return None
    centroid = np.concatenate(list(c_lo.values())).mean(axis=0)
    axis = int(np.argmax(centroid))
    if centroid[axis] <= 0:
        notes.append(f"the fingers lie on the negative side of every axis of {ee_link!r}: pick an ee_link whose "
                     "+x, +y or +z points at the fingertips")
    # Opening: the leader limit with the wider pad gap.
    pair_lo = _finger_pair(c_lo, axis)
    gap_lo = _gap(c_lo, pair_lo, axis)
    gap_hi = _gap(c_hi, pair_lo, axis) if all(f in c_hi for f in pair_lo) else 0.0
    open_q, closed_q, clouds_open = (hi, lo, c_hi) if gap_hi > gap_lo else (lo, hi, c_lo)
    pair = _finger_pair(clouds_open, axis)
    a, b = (_pad_center(clouds_open[f], axis) for f in pair)
    tcp = float((a[axis] + b[axis]) / 2)
    d = b - a
    d[axis] = 0.0
    closing = AXES[int(np.argmax(np.abs(d)))]
    if closing == AXES[axis]:
        closing = _other_axis(AXES[axis])
    width_open, width_closed = max(gap_lo, gap_hi), min(gap_lo, gap_hi)
    efforts = [urdf.joints[j].effort for j in leaders]
    force = float(min(e for e in efforts if e > 0)) if any(e > 0 for e in efforts) else 40.0
    notes.append(f"gripper max_force {force:g} is the URDF effort limit of {leaders}: check it against the object "
                 "(too much torque tilts linkage fingers)")
    notes.append(f"tcp_offset {tcp:.4f} m is the finger-pad midpoint with the gripper open; grasp a test object and adjust")
    g = GripperDraft(leaders, [round(open_q[j], 6) for j in leaders], [round(closed_q[j], 6) for j in leaders],
                     list(pair), round(max(width_open, 1e-3), 4), round(max(width_closed, 0.0), 4), force, closing)
    return g, AXES[axis], tcp


def _finger_pair(clouds: dict[str, np.ndarray], axis: int) -> tuple[str, str]:
    """The link reaching furthest along ``axis`` and the furthest-reaching one across from it."""
    tips = sorted(clouds, key=lambda ln: -clouds[ln][:, axis].max())
    first = tips[0]
    ca = _pad_center(clouds[first], axis)
    for other in tips[1:]:
        d = _pad_center(clouds[other], axis) - ca
        d[axis] = 0.0
        if np.linalg.norm(d) > MIN_FINGER_SEPARATION:
            return first, other
    return first, tips[1]


def _gap(clouds: dict[str, np.ndarray], pair: tuple[str, str], axis: int) -> float:
    """Gap (m) between the two pads' facing sides, along the pad-to-pad line."""
    a, b = (_pad_center(clouds[f], axis) for f in pair)
    d = b - a
    d[axis] = 0.0
    n = np.linalg.norm(d)
    if n < 1e-9:
        return 0.0
    u = d / n

    def pad(f: str) -> np.ndarray:
        P = clouds[f]
        return P[P[:, axis] >= P[:, axis].max() - PAD_LENGTH]

    return float(max(0.0, (pad(pair[1]) @ u).min() - (pad(pair[0]) @ u).max()))


def _other_axis(axis: str) -> str:
    return "y" if axis != "y" else "z"


def _r_ee_graspnet(ee_axis: str, closing: str) -> list[list[float]]:
    """Rows: grasp x (approach = +ee_axis), y (closing = +closing axis), z = x × y, in ee coordinates."""
    x = np.eye(3)[AXES.index(ee_axis)]
    y = np.eye(3)[AXES.index(closing)]
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


def render_yaml(d: RobotDraft) -> str:
    """The draft as a commented robot YAML (``schema_version: 1``). ``# CHECK`` marks guesses."""

    def vec(v) -> str:
        return "[" + ", ".join(_num(x) for x in v) + "]"

    lines = [
        "# Draft written by `robocfg new-robot`: every value comes from the URDF's structure and geometry.",
        "# Lines marked CHECK are estimates a person must confirm; then run `robocfg validate` and",
        "# `robocfg run gripper|trajectory|pick-place --robot THIS_FILE`.",
        "schema_version: 1",
        f"name: {d.name}",
        f"description: {d.name} (drafted by robocfg new-robot from its URDF)",
        f"urdf: {d.urdf_uri}",
        "fixed_base: true",
        "arms:",
        "  - name: arm",
        "    # Longest serial chain of movable (non-mimic) joints, base to tip.",
        f"    joints: [{', '.join(d.arm_joints)}]",
        f"    base_link: {d.base_link}",
        f"    # CHECK: links rigidly attached to the last arm joint: {', '.join(d.ee_candidates)}",
        f"    ee_link: {d.ee_link}",
        "    # CHECK: finger-pad midpoint (gripper open) along ee_axis, measured from the finger geometry.",
        f"    tcp_offset: {_num(d.tcp_offset)}",
        f"    ee_axis: {d.ee_axis}",
        f"    # Grasp x (approach) = ee +{d.ee_axis}"
        + (f", y (closing) = ee +{d.gripper.closing_axis}" if d.gripper else " (no gripper found: CHECK the rest)")
        + ", z = x × y.",
        f"    R_ee_graspnet: [{', '.join(vec(r) for r in d.R_ee_graspnet)}]",
        "    # CHECK: 0 where allowed, else mid-limits. Choose a pose clear of the table, tool down.",
        f"    home: {vec(d.home)}",
        f"    home_std: {vec([0.05] * len(d.home))}",
    ]
    g = d.gripper
    if g is not None:
        lines += [
            "    gripper:",
            "      type: parallel",
            "      # Driven (leader) joints; their <mimic> followers are coupled from the URDF.",
            f"      joints: [{', '.join(g.joints)}]",
            f"      open: {vec(g.open)}",
            f"      closed: {vec(g.closed)}",
            "      # Pad-face gaps measured from the geometry at the open and closed positions.",
            f"      max_width: {_num(g.max_width)}",
            f"      min_width: {_num(g.min_width)}",
            f"      finger_links: [{', '.join(g.finger_links)}]",
            "      # CHECK: the URDF effort limit; linkage grippers often need much less.",
            f"      max_force: {_num(g.max_force)}",
            "      lateral_friction: 1.0",
            "    collision_filter:",
            f"      ignore_links: [{', '.join(g.finger_links)}]",
        ]
    else:
        lines += ["    # CHECK: no gripper joints found. For a suction cup:",
                  "    # gripper: {type: suction, link: CUP_LINK, hold_force: 50.0}"]
    lines += [
        "drives:",
        "  # CHECK: PyBullet position-drive gains; raise max_force (N·m) for heavy arms.",
        "  arm: {stiffness: 0.1, damping: 1.0, max_force: 200.0}",
        "physics:",
        "  solver_iterations: 150",
        "  self_collision: true",
    ]
    if d.massless:
        lines += ["  # CHECK: these moving links have no <inertial> (PyBullet would make each 1 kg).",
                  "  link_masses:"] + [f"    {ln}: 0.01" for ln in d.massless]
    lines.append("ik_backend: lm")
    return "\n".join(lines) + "\n"


def _num(v: float) -> str:
    v = float(v)
    if v == 0:
        return "0.0"
    return repr(round(v, 6))
