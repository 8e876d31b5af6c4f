"""Load a robot YAML, validate its schema, and cross-check it against its URDF.

Errors stop the robot from being used; warnings are reported (``--strict`` makes them errors).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from robocfg.assets.fingers import (
    FingerGeometryMissing,
    closing_axis,
    finger_points,
    pad_midpoint,
    pad_points,
)
from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf import Urdf, UrdfParseError, missing_link_mass, parse_urdf
from robocfg.checks.tool_point import check_one_jaw, check_suction
from robocfg.config.load import Loc, YamlDocument, load_yaml
from robocfg.config.robot import (
    ArmConfig,
    OneJawGripperConfig,
    ParallelGripperConfig,
    RobotConfig,
    SuctionGripperConfig,
)
from robocfg.config.types import AXIS_INDEX
from robocfg.config.validation import validate_document
from robocfg.errors import ConfigError, Problem
from robocfg.suggest import did_you_mean

ROT_TOL = 1e-6
TCP_WARN_DIST = 0.010  # m
TCP_WARN_ANGLE_DEG = 10.0
TCP_ERROR_ANGLE_DEG = 45.0  # past this, ee_axis does not point at the fingers at all: an error


@dataclass
class CheckedRobot:
    """A robot YAML that passed its checks, with the parsed URDF and the resolved arm joints."""

    config: RobotConfig
    doc: YamlDocument
    urdf_path: Path
    urdf: Urdf
    warnings: list[Problem] = field(default_factory=list)
    sources: tuple[Path, ...] = ()  # the URDFs composed into urdf_path (robot + attachments), if any

    @property
    def path(self) -> Path:
        return self.doc.path

    def arm_joints(self, arm: ArmConfig) -> list[str]:
        """Arm joint names (from names, or from DOF indices)."""
        if arm.joints is not None:
            return list(arm.joints)
        return [self.urdf.dof_joints[i] for i in arm.joint_indices or []]

    def gripper_joints(self, arm: ArmConfig) -> list[str]:
        g = arm.gripper
        if not isinstance(g, ParallelGripperConfig):
            return []
        if g.joints is not None:
            return list(g.joints)
        return [self.urdf.dof_joints[i] for i in g.gripper_indices or []]

    def mimic_followers(self, leaders: list[str]) -> list[str]:
        return [j.name for j in self.urdf.joints.values() if j.mimic is not None and j.mimic.joint in leaders]


class _Collector:
    def __init__(self, doc: YamlDocument):
        self.doc = doc
        self.problems: list[Problem] = []

    def error(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg))

    def warn(self, loc: Loc, msg: str) -> None:
        self.problems.append(self.doc.problem(loc, msg, "warning"))


_CACHE: dict[tuple, tuple[CheckedRobot, tuple]] = {}
_CACHE_SIZE = 32


def load_robot(path: str | Path, strict: bool = False) -> CheckedRobot:
    """Load and check a robot YAML. Raises ConfigError listing every error (and, if strict, warning).

    Valid robots are memoised per process, keyed on the YAML's path and content and checked
    against the URDF's size and mtime, so validating many tasks that name the same robot parses
    its URDF and meshes once. Each call gets its own ``CheckedRobot`` and warnings list."""
    p = Path(path)
    try:
        key: tuple | None = (p.resolve(), hashlib.sha1(p.read_bytes()).hexdigest(), strict)
    except OSError:
        key = None
    hit = _CACHE.get(key) if key is not None else None
    if hit is not None and _stat_key(hit[0].urdf_path, *hit[0].sources) == hit[1]:
        robot = hit[0]
    else:
        robot = _load_robot(p, strict)
        if key is not None:
            if len(_CACHE) >= _CACHE_SIZE:
                _CACHE.pop(next(iter(_CACHE)))
            _CACHE[key] = (robot, _stat_key(robot.urdf_path, *robot.sources))
    return replace(robot, warnings=list(robot.warnings))


def _stat_key(*paths: Path) -> tuple:
    out: tuple = ()
    for path in paths:
        try:
            st = path.stat()
        except OSError:
            return ()
        out += (st.st_size, st.st_mtime_ns)
    return out


def _load_robot(path: Path, strict: bool) -> CheckedRobot:
    doc = load_yaml(path)
    config: RobotConfig = validate_document(doc, RobotConfig)
    c = _Collector(doc)
    resolver = Resolver(doc.path.parent, config.package_dirs)
    try:
        urdf_path = resolver.urdf(config.urdf)
    except UnresolvedPath as exc:
        raise ConfigError([doc.problem(("urdf",), f"URDF not found: {exc}")]) from None
    sources: tuple[Path, ...] = ()
    if config.attachments:
        composed = _compose(doc, config, resolver, urdf_path)  # ConfigError for a missing attachment
        sources = (urdf_path, *(resolver.urdf(a.urdf) for a in config.attachments))
        urdf_path = composed
    try:
        urdf = parse_urdf(urdf_path)
    except UrdfParseError as exc:
        line = f":{exc.line}" if exc.line else ""
        raise ConfigError([doc.problem(("urdf",), f"URDF {urdf_path}{line} does not parse: {exc}")]) from None
    robot = CheckedRobot(config, doc, urdf_path, urdf, sources=sources)
    _check_meshes(c, robot, resolver)
    for i, arm in enumerate(config.arms):
        _check_arm(c, robot, arm, ("arms", i), resolver)
    _check_drives_and_physics(c, robot)
    errors = [p for p in c.problems if p.severity == "error"]
    warnings = [p for p in c.problems if p.severity == "warning"]
    if errors or (strict and warnings):
        raise ConfigError(errors + (warnings if strict else []))
    robot.warnings = warnings
    return robot


def _compose(doc: YamlDocument, config: RobotConfig, resolver: Resolver, base: Path) -> Path:
    """Compose the URDF with ``attachments`` (cached file); ConfigError at the attachment's lines."""
    from robocfg.assets.compose import CompositionError, Part, compose, rpy_from_deg

    parts, problems = [], []
    for i, a in enumerate(config.attachments):
        try:
            path = resolver.urdf(a.urdf)
        except UnresolvedPath as exc:
            problems.append(doc.problem(("attachments", i, "urdf"), f"URDF not found: {exc}"))
            continue
        x, y, z = a.mount_xyz
        parts.append((i, Part(path, a.mount_link, (x, y, z), rpy_from_deg(a.mount_rpy_deg), a.name, a.prefix)))
    if problems:
        raise ConfigError(problems)
    try:
        return compose(base, [part for _, part in parts], resolver).path
    except CompositionError as exc:
        raise ConfigError([doc.problem(("urdf",) if pr.index is None else ("attachments", parts[pr.index][0], pr.key),
                                       pr.message) for pr in exc.problems]) from None
    except OSError as exc:
        raise ConfigError([doc.problem(("attachments",), f"cannot write the composed URDF: {exc}")]) from None


def _check_meshes(c: _Collector, robot: CheckedRobot, resolver: Resolver) -> None:
    for link in robot.urdf.links.values():
        for g in (*link.visuals, *link.collisions):
            if g.kind != "mesh" or not g.filename:
                continue
            try:
                resolver.mesh(g.filename, robot.urdf_path)
            except UnresolvedPath as exc:
                tried = ", ".join(str(t) for t in exc.tried)
                c.error(("urdf",), f"mesh {g.filename!r} of link {link.name!r} not found; tried: {tried}")


def _known(c: _Collector, loc: Loc, name: str, names: list[str], kind: str) -> bool:
    if name in names:
        return True
    c.error(loc, f"no {kind} {name!r} in the URDF{did_you_mean(name, names)}")
    return False


def _check_arm(c: _Collector, robot: CheckedRobot, arm: ArmConfig, loc: Loc, resolver: Resolver) -> None:
    urdf = robot.urdf
    links = list(urdf.links)
    ok_links = _known(c, (*loc, "base_link"), arm.base_link, links, "link")
    ok_links &= _known(c, (*loc, "ee_link"), arm.ee_link, links, "link")
    names_ok = _check_joint_list(c, urdf, arm.joints, arm.joint_indices, loc, "joints", "joint_indices")
    if not names_ok:
        return
    arm_joints = robot.arm_joints(arm)
    if ok_links:
        chain = urdf.chain(arm.base_link, arm.ee_link)
        if chain is None:
            c.error((*loc, "ee_link"), f"ee_link {arm.ee_link!r} is not below base_link {arm.base_link!r} in the URDF tree")
        else:
            movable = [j.name for j in chain if j.movable]
            if movable != arm_joints:
                c.error((*loc, "joints" if arm.joints else "joint_indices"),
                        f"arm joints must form the serial chain of movable joints from base_link {arm.base_link!r} to ee_link {arm.ee_link!r}, in order: expected {movable}, got {arm_joints}")
    # R_ee_graspnet
    R = np.asarray(arm.R_ee_graspnet, dtype=float)
    if not np.allclose(R @ R.T, np.eye(3), atol=ROT_TOL) or abs(np.linalg.det(R) - 1) > ROT_TOL:
        c.error((*loc, "R_ee_graspnet"), f"must be a rotation (orthonormal, det +1); R·Rᵀ deviates by {np.abs(R @ R.T - np.eye(3)).max():.2e}, det = {np.linalg.det(R):.4f}")
    else:
        col = R[:, AXIS_INDEX[arm.ee_axis]]
        if not np.allclose(col, [1, 0, 0], atol=ROT_TOL):
            c.error((*loc, "R_ee_graspnet"),
                    f"column {AXIS_INDEX[arm.ee_axis]} (ee_axis '{arm.ee_axis}') must be (1, 0, 0): the EE approach axis is the grasp frame's x; got {np.round(col, 6).tolist()}")
    # home within limits
    for k, (jn, q) in enumerate(zip(arm_joints, arm.home, strict=True)):
        j = urdf.joints[jn]
        if j.type == "continuous":
            continue
        if not (j.lower - 1e-9 <= q <= j.upper + 1e-9):
            c.error((*loc, "home", k), f"home of {jn} = {q:.4f} is outside the limits [{j.lower:.4f}, {j.upper:.4f}]")
        elif arm.home_std is not None:
            s = 3 * arm.home_std[k]
            if q - s < j.lower or q + s > j.upper:
                c.warn((*loc, "home_std", k), f"home ± 3·std for {jn} ({q - s:.3f}..{q + s:.3f}) leaves the limits [{j.lower:.3f}, {j.upper:.3f}]")
    for key in ("ignore_links", "forbid_links"):
        for k, ln in enumerate(getattr(arm.collision_filter, key)):
            _known(c, (*loc, "collision_filter", key, k), ln, links, "link")
    g = arm.gripper
    if isinstance(g, ParallelGripperConfig):
        _check_parallel(c, robot, arm, g, (*loc, "gripper"), resolver)
    elif isinstance(g, SuctionGripperConfig) and _known(c, (*loc, "gripper", "link"), g.link, links, "link"):
        chain = urdf.chain(arm.ee_link, g.link) if arm.ee_link in links else []
        if chain is None or any(j.movable for j in chain):
            c.error((*loc, "gripper", "link"), f"suction link {g.link!r} must be rigidly attached below ee_link {arm.ee_link!r}")
        else:
            check_suction(c.warn, urdf, resolver, arm, g, (*loc, "tcp_offset"), (*loc, "gripper", "link"))


def _check_joint_list(c: _Collector, urdf: Urdf, names: list[str] | None, indices: list[int] | None,
                      loc: Loc, name_key: str, index_key: str) -> bool:
    ok = True
    joints = list(urdf.joints)
    if names is not None:
        for k, n in enumerate(names):
            if not _known(c, (*loc, name_key, k), n, joints, "joint"):
                ok = False
            elif not urdf.joints[n].movable:
                c.error((*loc, name_key, k), f"joint {n!r} is {urdf.joints[n].type}, not movable")
                ok = False
    if indices is not None:
        ndof = len(urdf.dof_joints)
        for k, i in enumerate(indices):
            if not 0 <= i < ndof:
                c.error((*loc, index_key, k), f"DOF index {i} is out of range: the URDF has {ndof} movable joints (0..{ndof - 1}){_pybullet_hint(urdf, i)}")
                ok = False
            elif names is not None and k < len(names) and urdf.dof_joints[i] != names[k]:
                c.error((*loc, index_key, k), f"DOF index {i} is {urdf.dof_joints[i]!r} but {name_key}[{k}] is {names[k]!r}{_pybullet_hint(urdf, i)}")
                ok = False
    return ok


def _pybullet_hint(urdf: Urdf, i: int) -> str:
    """Hint for the classic mistake of giving a PyBullet joint index (fixed joints counted)."""
    by_index = {j.urdf_index: j for j in urdf.joints.values()}
    j = by_index.get(i)
    if j is None:
        return ""
    if j.movable:
        return f"; PyBullet joint index {i} is {j.name!r}, whose DOF index is {urdf.dof_index(j.name)} (indices here are DOF indices, see `robocfg inspect`)"
    return f"; PyBullet joint index {i} is the {j.type} joint {j.name!r} (indices here are DOF indices: fixed joints have none, see `robocfg inspect`)"


def _check_parallel(c: _Collector, robot: CheckedRobot, arm: ArmConfig, g: ParallelGripperConfig,
                    loc: Loc, resolver: Resolver) -> None:
    urdf = robot.urdf
    if not _check_joint_list(c, urdf, g.joints, g.gripper_indices, loc, "joints", "gripper_indices"):
        return
    leaders = robot.gripper_joints(arm)
    arm_joints = set(robot.arm_joints(arm)) if (arm.joints or arm.joint_indices) else set()
    key = "joints" if g.joints is not None else "gripper_indices"
    for k, jn in enumerate(leaders):
        j = urdf.joints[jn]
        if jn in arm_joints:
            c.error((*loc, key, k), f"gripper joint {jn!r} is also an arm joint")
        if arm.ee_link in urdf.descendants(jn):
            c.error((*loc, key, k), f"gripper joint {jn!r} moves ee_link {arm.ee_link!r}: the EE→TCP transform must be fixed; pick a link above the fingers")
        if j.mimic is not None:
            c.error((*loc, key, k), f"gripper joint {jn!r} is a mimic follower of {j.mimic.joint!r} (URDF <mimic>); list only the driven joint(s) — followers are geared automatically")
        for key in ("open", "closed"):
            v = getattr(g, key)[k]
            if not (j.lower - 1e-9 <= v <= j.upper + 1e-9):
                c.error((*loc, key, k), f"{key} position {v} of {jn} is outside the limits [{j.lower}, {j.upper}]")
    finger_ok = all(_known(c, (*loc, "finger_links", k), f, list(urdf.links), "link") for k, f in enumerate(g.finger_links))
    if finger_ok and arm.ee_link in urdf.links:
        _check_tcp(c, robot, arm, g, leaders, loc, resolver)
        if isinstance(g, OneJawGripperConfig):
            check_one_jaw(c.warn, urdf, resolver, arm, g, leaders, loc)


def _check_tcp(c: _Collector, robot: CheckedRobot, arm: ArmConfig, g: ParallelGripperConfig,
               leaders: list[str], loc: Loc, resolver: Resolver) -> None:
    """The finger-pad midpoint (by FK) must lie along +ee_axis, and ``tcp_offset`` within the range
    that midpoint covers between ``open`` and ``closed`` (± TCP_WARN_DIST): on linkage grippers
    (Robotiq) the pads move along the approach axis as they close, so the TCP depends on the width."""
    urdf = robot.urdf
    axis = AXIS_INDEX[arm.ee_axis]
    try:
        points = finger_points(urdf, resolver, list(g.finger_links))
    except FingerGeometryMissing as exc:
        if "no geometry" in str(exc):
            c.warn((*loc, "finger_links"), f"{exc}; cannot check tcp_offset")
        return  # a missing mesh is already reported
    mids = [pad_midpoint(pad_points(urdf, arm.ee_link, list(g.finger_links), points, dict(zip(leaders, qs, strict=True)), axis))
            for qs in (g.open, g.closed)]
    mid = mids[0].copy()
    if isinstance(g, OneJawGripperConfig):  # its grasp centre is off the axis by design (grasp_side_shift)
        c_dir = closing_axis(arm.R_ee_graspnet)
        mid -= (mid @ c_dir) * c_dir
    along = mid[axis]
    angle = np.degrees(np.arccos(np.clip(along / max(np.linalg.norm(mid), 1e-9), -1, 1)))
    lo, hi = sorted(float(m[axis]) for m in mids)
    tcp_loc = ("arms", robot.config.arms.index(arm), "tcp_offset")
    span = f"{along:.4f} m" if hi - lo < 1e-4 else f"{mids[0][axis]:.4f} m open, {mids[1][axis]:.4f} m closed"
    if along <= 0 or angle > TCP_ERROR_ANGLE_DEG:
        c.error((*loc[:-1], "ee_axis"), f"the finger pads (gripper open) are {angle:.0f}° away from +{arm.ee_axis} of ee_link "
                f"(midpoint {np.round(mid, 4).tolist()} m in the ee_link frame); ee_axis must point from ee_link towards the fingertips")
    elif not lo - TCP_WARN_DIST <= arm.tcp_offset <= hi + TCP_WARN_DIST or angle > TCP_WARN_ANGLE_DEG:
        c.warn(tcp_loc, f"finger-pad midpoint is {span} along {arm.ee_axis} and {angle:.1f}° off the axis; tcp_offset is {arm.tcp_offset:.4f} m")


def _check_drives_and_physics(c: _Collector, robot: CheckedRobot) -> None:
    cfg, urdf = robot.config, robot.urdf
    driven = {n for a in cfg.arms for n in robot.arm_joints(a) + robot.gripper_joints(a)}
    for name, q in cfg.locked_joints.items():
        loc = ("locked_joints", name)
        if not _known(c, loc, name, [j.name for j in urdf.joints.values() if j.movable], "movable joint"):
            continue
        j = urdf.joints[name]
        if name in driven:
            c.error(loc, f"{name!r} is an arm or gripper joint: it is driven, not locked (remove it from one of the two)")
        elif j.mimic is not None:
            c.error(loc, f"{name!r} follows {j.mimic.joint!r} by a <mimic> tag: lock the leader instead")
        elif not j.lower <= q <= j.upper:
            c.error(loc, f"{name} = {q:.4f} is outside the limits [{j.lower:.4f}, {j.upper:.4f}]")
    for key in ("velocity_limits", "acceleration_limits"):
        for name in getattr(cfg.drives, key):
            _known(c, ("drives", key, name), name, list(urdf.joints), "joint")
    for name in cfg.physics.link_masses:
        _known(c, ("physics", "link_masses", name), name, list(urdf.links), "link")
    # Every link but the root counts: a fixed-joint child (a flange frame, a finger pad, an
    # attachment's root) weighs on the arm and the gripper as much as a moving one.
    for j in urdf.joints.values():
        link = urdf.links.get(j.child)
        if not link or j.child in cfg.physics.link_masses:
            continue
        if link.mass is None:
            c.warn(("physics", "link_masses"), f"link {j.child!r} has no <inertial>: PyBullet would make it 1 kg, robocfg "
                   f"loads it as {missing_link_mass(link):g} kg; set physics.link_masses.{j.child} to its real mass")
        elif link.mass <= 0 and j.movable:
            c.warn(("physics", "link_masses"), f"moving link {j.child!r} has zero mass; set physics.link_masses.{j.child}")
