"""Load a robot YAML, validate its schema, and cross-check it against its URDF (the meshes, the
drives and physics blocks here; each arm and its gripper in :mod:`robocfg.checks.arm`).

Errors stop the robot from being used; warnings are reported (``--strict`` makes them errors).
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf import Urdf, UrdfParseError, missing_link_mass
from robocfg.assets.urdf_xml import parse_urdf
from robocfg.checks.arm import Collector, check_arm, known
from robocfg.config.load import YamlDocument, load_yaml
from robocfg.config.robot import ArmConfig, ParallelGripperConfig, RobotConfig
from robocfg.config.types import AXIS_INDEX
from robocfg.config.validation import validate_document
from robocfg.errors import ConfigError, Problem


@dataclass
class CheckedRobot:
    """A robot YAML that passed its checks, with the parsed URDF and the resolved arm joints."""

    config: RobotConfig
    doc: YamlDocument
    urdf_path: Path
    urdf: Urdf
    warnings: list[Problem] = field(default_factory=list)
    sources: tuple[Path, ...] = ()  # the URDFs composed into urdf_path (robot + attachments), if any
    # pad_gap_curve answers by arm (the config check, the gripper and the pick-place session ask)
    _pad_curves: dict[str, tuple[np.ndarray, np.ndarray] | None] = field(default_factory=dict, init=False, repr=False,
                                                                       compare=False)

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

    def pad_gap_curve(self, arm: ArmConfig) -> tuple[np.ndarray, np.ndarray] | None:
        """(opening fraction s ∈ [0, 1], 0 = closed, 1 = open; pad gap in m) over the travel of
        ``arm``'s parallel gripper, by FK of the URDF's finger geometry
        (:func:`robocfg.assets.fingers.width_curve`); None for a suction cup or where the finger
        geometry is missing."""
        from robocfg.assets.fingers import FingerGeometryMissing, closing_axis, width_curve

        g = arm.gripper
        if not isinstance(g, ParallelGripperConfig):
            return None
        key = repr(arm)  # computed once per arm config (≈ 0.06 s; asked up to 3 times before an episode)
        if key not in self._pad_curves:
            try:
                s, gaps = width_curve(self.urdf, Resolver(self.path.parent, self.config.package_dirs), arm.ee_link,
                                      AXIS_INDEX[arm.ee_axis], list(g.finger_links), self.gripper_joints(arm),
                                      g.open, g.closed, closing_axis(arm.R_ee_graspnet))
                s.setflags(write=False)  # shared by every caller
                gaps.setflags(write=False)
                self._pad_curves[key] = (s, gaps)
            except (FingerGeometryMissing, KeyError, ValueError):
                self._pad_curves[key] = None
        return self._pad_curves[key]

    def mimic_followers(self, leaders: list[str]) -> list[str]:
        return [j.name for j in self.urdf.joints.values() if j.mimic is not None and j.mimic.joint in leaders]


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
    c = Collector(doc)
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
        check_arm(c, robot, arm, ("arms", i), resolver)
    _check_drives_and_physics(c, robot)
    errors = [p for p in c.problems if p.severity == "error"]
    warnings = [p for p in c.problems if p.severity == "warning"]
    if errors or (strict and warnings):
        raise ConfigError(errors + (warnings if strict else []))
    robot.warnings = warnings
    return robot


def _compose(doc: YamlDocument, config: RobotConfig, resolver: Resolver, base: Path) -> Path:
    """Compose the URDF with ``attachments`` (cached file); ConfigError at the attachment's lines."""
    from robocfg.assets.compose import CompositionError, Part, compose

    parts, problems = [], []
    for i, a in enumerate(config.attachments):
        try:
            path = resolver.urdf(a.urdf)
        except UnresolvedPath as exc:
            problems.append(doc.problem(("attachments", i, "urdf"), f"URDF not found: {exc}"))
            continue
        parts.append((i, Part.of(a, path)))
    if problems:
        raise ConfigError(problems)
    try:
        return compose(base, [part for _, part in parts], resolver).path
    except CompositionError as exc:
        raise ConfigError([doc.problem(("urdf",) if pr.index is None else ("attachments", parts[pr.index][0], pr.key),
                                       pr.message) for pr in exc.problems]) from None
    except OSError as exc:
        raise ConfigError([doc.problem(("attachments",), f"cannot write the composed URDF: {exc}")]) from None


def _check_meshes(c: Collector, robot: CheckedRobot, resolver: Resolver) -> None:
    for link in robot.urdf.links.values():
        for g in (*link.visuals, *link.collisions):
            if g.kind != "mesh" or not g.filename:
                continue
            try:
                resolver.mesh(g.filename, robot.urdf_path)
            except UnresolvedPath as exc:
                tried = ", ".join(str(t) for t in exc.tried)
                c.error(("urdf",), f"mesh {g.filename!r} of link {link.name!r} not found; tried: {tried}")


def _check_drives_and_physics(c: Collector, robot: CheckedRobot) -> None:
    cfg, urdf = robot.config, robot.urdf
    driven = {n for a in cfg.arms for n in robot.arm_joints(a) + robot.gripper_joints(a)}
    for name, q in cfg.locked_joints.items():
        loc = ("locked_joints", name)
        if not known(c, loc, name, [j.name for j in urdf.joints.values() if j.movable], "movable joint"):
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
            known(c, ("drives", key, name), name, list(urdf.joints), "joint")
    for name in cfg.physics.link_masses:
        known(c, ("physics", "link_masses", name), name, list(urdf.links), "link")
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
