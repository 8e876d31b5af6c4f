"""Map an InternDataEngine robot config onto robocfg's robot YAML fields, checked against the URDF.

* prim paths (``fl_ee_path``, ``fl_base_path``, filter paths) → link names by their last element;
  a last element with regex characters (their ``*_paths_expr`` use) matches link names;
* Isaac articulation DOF indices → joint names through :func:`isaac_dof_order`, then checked to be
  the movable chain from the base link to the EE link (a hint when they are URDF-order indices);
* gripper indices → the driven joints (``<mimic>`` followers are geared by robocfg: dropped);
* keypoints → ``gripper_keypoints``, cross-checked with ``tcp_offset`` and ``ee_axis``;
* ``*_joint_home_std`` → ``home_std`` (home randomisation).

Every problem is reported at its line in *their* file. ``origin`` records, for each field of the
result, the key of their file it came from, so later checks can point there too.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from robocfg.assets.urdf import Urdf
from robocfg.config.load import Loc, YamlDocument
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import ConfigError, Problem
from robocfg.interop.interndata_schema import SIDE_PREFIX, InterndataRobot
from robocfg.interop.isaac_order import isaac_dof_order
from robocfg.suggest import did_you_mean

KEYPOINT_ERROR_DEG = 45.0  # tool_tail → tool_head further than this from +ee_axis: ee_axis is wrong
KEYPOINT_WARN_DIST = 0.01  # m: tool_head's distance along ee_axis vs tcp_offset


@dataclass(frozen=True)
class Dropped:
    """A key of their file that robocfg does not keep, and why."""

    key: str
    why: str


@dataclass
class Mapped:
    """Our robot fields mapped from their file (``arms`` etc.), plus provenance and notes."""

    robot: dict[str, Any]
    origin: dict[str, tuple[Loc, bool]] = field(default_factory=dict)  # our loc → (their loc, index suffix applies)
    dropped: list[Dropped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    warnings: list[Problem] = field(default_factory=list)  # on their file
    leaders: dict[int, list[str]] = field(default_factory=dict)  # arm index → driven gripper joints


class _Mapper:
    def __init__(self, doc: YamlDocument, their: InterndataRobot, urdf: Urdf):
        self.doc, self.their, self.urdf = doc, their, urdf
        self.problems: list[Problem] = []
        self.isaac = isaac_dof_order(urdf)

    def error(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg))

    def warn(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg, "warning"))

    def link(self, key: str, path: str, loc: Loc | None = None) -> str | None:
        """The URDF link a prim path names (its last element)."""
        name = path.rstrip("/").rsplit("/", 1)[-1]
        if name in self.urdf.links:
            return name
        self.error(loc or (key,), f"prim path {path!r}: no link {name!r} in the URDF (the last path element must be a "
                   f"link name){did_you_mean(name, list(self.urdf.links))}")
        return None

    def links(self, key: str, paths: list[str]) -> list[str]:
        out: list[str] = []
        for k, p in enumerate(paths):
            if not p:
                continue
            last = p.rstrip("/").rsplit("/", 1)[-1]
            if re.search(r"[.*+?\[\]()|^$]", last):
                try:
                    hits = [ln for ln in self.urdf.links if re.fullmatch(last, ln)]
                except re.error as exc:
                    self.error((key, k), f"prim path expression {p!r} is not a valid regular expression: {exc}")
                    continue
                if not hits:
                    self.error((key, k), f"prim path expression {p!r} matches no link of the URDF")
                out += [h for h in hits if h not in out]
            else:
                ln = self.link(key, p, (key, k))
                if ln is not None and ln not in out:
                    out.append(ln)
        return out

    def joints(self, key: str, indices: list[int]) -> list[str] | None:
        """Joint names for Isaac DOF indices, or None (problems recorded)."""
        n = len(self.isaac)
        bad = [k for k, i in enumerate(indices) if i >= n]
        for k in bad:
            self.error((key, k), f"DOF index {indices[k]} is out of range: the URDF has {n} movable joints (0..{n - 1})")
        return None if bad else [self.isaac[i] for i in indices]


def map_interndata(doc: YamlDocument, their: InterndataRobot, urdf: Urdf) -> Mapped:
    """Our robot fields for ``their`` (parsed from ``doc``) on ``urdf``. Raises ConfigError (their file's lines)."""
    m = _Mapper(doc, their, urdf)
    out = Mapped({"arms": [], "physics": {"solver_iterations": their.solver_position_iteration_count}})
    out.origin["physics.solver_iterations"] = (("solver_position_iteration_count",), False)
    dual = len(their.sides) == 2
    taken: dict[str, str] = {}  # joint → the arm or gripper that drives it
    for i, side in enumerate(their.sides):
        arm = _map_arm(m, out, i, side, "arm" if not dual else side)
        taken.update({j: f"a {side} arm joint" for j in arm.get("joints", [])})
        taken.update({j: f"a {side} gripper joint" for j in out.leaders.get(i, [])})
        out.robot["arms"].append(arm)
    if their.lift_indices:
        names = m.joints("lift_indices", their.lift_indices) or []
        for k, jn in enumerate(names):
            if jn in taken:
                m.error(("lift_indices", k), f"DOF index {their.lift_indices[k]} is {jn!r}, {taken[jn]}")
        out.dropped.append(Dropped("lift_indices / lift_home", f"robocfg has no lift joint group: {names} stay at their URDF "
                            "zero position (they are checked to exist and to be outside the arms)"))
    for key, why in (("target_class", "robocfg robots are data, not Python classes"),
                     ("path", "a USD for Isaac Sim; robocfg loads the URDF"),
                     ("robot_file", "CuRobo configs; robocfg's kinematics come from the URDF (pinocchio)"),
                     ("solver_velocity_iteration_count", "PhysX only; PyBullet has one solver iteration count"),
                     ("stabilization_threshold", "PhysX only")):
        if key in doc.data:
            out.dropped.append(Dropped(key, why))
    errors = [p for p in m.problems if p.severity == "error"]
    if errors:
        raise ConfigError(m.problems)
    out.warnings += m.problems
    return out


def _map_arm(m: _Mapper, out: Mapped, i: int, side: str, name: str) -> dict[str, Any]:
    t, urdf, fx = m.their, m.urdf, SIDE_PREFIX[side]
    arm: dict[str, Any] = {"name": name}
    here = f"arms[{i}]"

    def put(key: str, value: Any, their_key: str, suffix: bool = True) -> None:
        arm[key] = value
        out.origin[f"{here}.{key}"] = ((their_key,), suffix)

    base = m.link(f"{fx}_base_path", getattr(t, f"{fx}_base_path"))
    ee = m.link(f"{fx}_ee_path", getattr(t, f"{fx}_ee_path"))
    joints = m.joints(f"{side}_joint_indices", getattr(t, f"{side}_joint_indices"))
    grip = m.joints(f"{side}_gripper_indices", getattr(t, f"{side}_gripper_indices"))
    put("base_link", base, f"{fx}_base_path")
    put("ee_link", ee, f"{fx}_ee_path")
    put("tcp_offset", t.tcp_offset, "tcp_offset")
    put("ee_axis", t.ee_axis, "ee_axis")
    put("R_ee_graspnet", t.R_ee_graspnet, "R_ee_graspnet")
    put("home", getattr(t, f"{side}_joint_home"), f"{side}_joint_home")
    if getattr(t, f"{side}_joint_home_std"):
        put("home_std", getattr(t, f"{side}_joint_home_std"), f"{side}_joint_home_std")
    ee_fixed = True
    if ee is not None and grip:
        moving = [j for j in [*grip, *_followers(urdf, grip)] if ee in urdf.descendants(j)]
        if moving:
            ee_fixed = False
            above = urdf.joints[moving[0]].parent
            m.error((f"{fx}_ee_path",), f"EE link {ee!r} moves with gripper joint {moving[0]!r}: the transform from the EE "
                    f"to the TCP must be fixed; pick a link above the fingers (e.g. {above!r})")
    if joints is not None:
        put("joints", joints, f"{side}_joint_indices")
        if base is not None and ee is not None and ee_fixed:
            chain = urdf.chain(base, ee)
            if chain is None:
                m.error((f"{fx}_ee_path",), f"EE link {ee!r} is not below the base link {base!r} in the URDF tree")
            else:
                movable = [j.name for j in chain if j.movable]
                if movable != joints:
                    m.error((f"{side}_joint_indices",), _index_message(urdf, m.isaac, movable, joints, base, ee))
    if grip:
        followers = [j for j in grip if j in _followers(urdf, grip)]
        leaders = [j for j in grip if j not in followers]
        if followers:
            out.dropped.append(Dropped(f"{side}_gripper_indices", f"{followers} follow {leaders} through URDF <mimic> tags; "
                                "robocfg drives the leader and gears the followers"))
        home = getattr(t, f"{side}_gripper_home")
        gripper: dict[str, Any] = {"type": "parallel", "joints": leaders}
        out.origin[f"{here}.gripper"] = ((f"{side}_gripper_indices",), False)
        if home:
            gripper["open"] = [home[grip.index(j)] for j in leaders]
            out.origin[f"{here}.gripper.open"] = ((f"{side}_gripper_home",), False)
        if t.gripper_max_width > 0:
            gripper["max_width"] = t.gripper_max_width
            gripper["min_width"] = t.gripper_min_width
            out.origin[f"{here}.gripper.max_width"] = (("gripper_max_width",), False)
            out.origin[f"{here}.gripper.min_width"] = (("gripper_min_width",), False)
        arm["gripper"] = gripper
        out.leaders[i] = leaders
    kp = getattr(t, f"{fx}_gripper_keypoints")
    if kp is not None:
        put("gripper_keypoints", {k: list(getattr(kp, k)[:3]) for k in ("tool_head", "tool_tail", "tool_side")},
            f"{fx}_gripper_keypoints")
        _check_keypoints(m, fx, kp.tool_head[:3], kp.tool_tail[:3], t.ee_axis, t.tcp_offset)
    cf: dict[str, list[str]] = {}
    for ours, theirs in (("ignore_links", f"{fx}_filter_paths"), ("forbid_links", f"{fx}_forbid_collision_paths")):
        paths = getattr(t, theirs)
        if paths:
            cf[ours] = m.links(theirs, paths)
            out.origin[f"{here}.collision_filter.{ours}"] = ((theirs,), True)
    if cf:
        arm["collision_filter"] = cf
    return arm


def _followers(urdf: Urdf, leaders: list[str]) -> list[str]:
    """Joints that follow one of ``leaders`` through a URDF ``<mimic>`` tag."""
    return [j.name for j in urdf.joints.values() if j.mimic is not None and j.mimic.joint in leaders]


def _index_message(urdf: Urdf, isaac: list[str], movable: list[str], joints: list[str], base: str, ee: str) -> str:
    msg = (f"these Isaac DOF indices name {joints}, but the movable joints from {base!r} to {ee!r} are {movable} "
           f"(Isaac indices {[isaac.index(j) for j in movable]})")
    if [urdf.dof_joints[isaac.index(j)] for j in joints if isaac.index(j) < len(urdf.dof_joints)] == movable:
        msg += "; the indices given are the URDF-order (PyBullet) ones: Isaac Sim numbers DOFs breadth-first"
    return msg


def _check_keypoints(m: _Mapper, fx: str, head: list[float], tail: list[float], ee_axis: str, tcp: float) -> None:
    d = np.asarray(head, float) - np.asarray(tail, float)
    key = f"{fx}_gripper_keypoints"
    if np.linalg.norm(d) < 1e-9:
        m.warn((key, "tool_head"), "tool_head equals tool_tail: cannot cross-check ee_axis")
        return
    axis = AXIS_INDEX[ee_axis]
    angle = float(np.degrees(np.arccos(np.clip(d[axis] / np.linalg.norm(d), -1, 1))))
    if angle > KEYPOINT_ERROR_DEG:
        m.error((key, "tool_head"), f"tool_tail → tool_head points {angle:.0f}° away from +{ee_axis} of the EE link: "
                f"ee_axis must be the approach direction from the EE origin to the TCP (check ee_axis, or the keypoints)")
    elif abs(head[axis] - tcp) > KEYPOINT_WARN_DIST:
        m.warn((key, "tool_head"), f"tool_head lies {head[axis]:.4f} m along {ee_axis} but tcp_offset is {tcp:.4f} m")
