"""Kinematic model of one arm (pinocchio): FK of any frame, frame Jacobians, and IK.

Built from the same resolved URDF the simulator loads. Every joint that is not an arm joint is
locked (gripper leaders at their configured ``open`` value, mimic followers following, other arms
at their ``home``), the base mount is applied, and the TCP is a fixed frame ``"tcp"`` at
``tcp_offset`` along ``ee_axis`` of ``ee_link``.

Frames: every pose is ``world_T_frame`` (4x4, metres), where ``world_T_base`` is the mount pose of
the URDF's root link (identity if not given). Joint values are in arm-joint order (rad or m).
Continuous joints are modelled as revolute joints with limits [-π, π]; they and joints whose
range spans 2π or more are *wrapped* (not clamped) by the IK solvers.

pinocchio is imported here: import this module lazily from the CLI.

Length (≈ 450 lines): one concept, the model's construction (the last few builds kept and
copied) and its queries (FK, sampled FK positions, Jacobians, IK dispatch); the IK solvers
themselves live in :mod:`robocfg.kinematics.ik`.
"""

from __future__ import annotations

import math
import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from robocfg.config.types import AXIS_INDEX
from robocfg.errors import NotFound, RobocfgError

if TYPE_CHECKING:
    from collections.abc import Sequence

    from robocfg.checks.robot import CheckedRobot
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.ik.solver import IKSolver

TCP_FRAME = "tcp"


_XML_MEMO: dict[tuple[str, int, int], tuple[str, frozenset[str]]] = {}
# What urdfdom (pinocchio's parser) refuses or reads otherwise, and ElementTree's round trip writes
# plainly: a DOCTYPE (internal entities), a processing instruction after the XML declaration, a tab
# or line break inside an attribute value. Such a file is handed over re-serialised, as all were once.
_PLAIN_XML_ONLY_AFTER_ROUND_TRIP = re.compile(rb"<!DOCTYPE|(?<!^)<\?|=\s*\"[^\"]*[\t\r\n][^\"]*\"|=\s*'[^']*[\t\r\n][^']*'")


def _urdf_xml_without_continuous(path: str) -> tuple[str, frozenset[str]]:
    """The URDF text with continuous joints turned into revolute ones limited to [-π, π].

    pinocchio models continuous joints with two coordinates (cos, sin); one angle per joint keeps
    the interface simple. Returns (xml text, names of the converted joints); remembered per file
    (path, size, mtime): a process builds several models of one robot before its first episode.

    A file that cannot hold a continuous joint (the word ``continuous`` nowhere in it), is plain
    ASCII (no encoding or byte-order mark to interpret) and holds none of the XML that urdfdom reads
    otherwise than ElementTree (``_PLAIN_XML_ONLY_AFTER_ROUND_TRIP``) is returned as read: nothing to convert, and
    pinocchio builds the same model from it as from the parsed and re-serialised tree (compared for
    every shipped robot in ``tests/test_kinematics_model_memo.py``), without the ≈ 2 ms round trip.
    """
    from pathlib import Path

    st = os.stat(path)
    key = (path, st.st_size, st.st_mtime_ns)
    if key not in _XML_MEMO:
        if len(_XML_MEMO) >= 16:
            _XML_MEMO.pop(next(iter(_XML_MEMO)))
        data = Path(path).read_bytes()
        if b"continuous" not in data and data.isascii() and not _PLAIN_XML_ONLY_AFTER_ROUND_TRIP.search(data):
            _XML_MEMO[key] = (data.decode("ascii"), frozenset())
        else:
            _XML_MEMO[key] = _reserialised_xml(path)
    return _XML_MEMO[key]


def _reserialised_xml(path: str) -> tuple[str, frozenset[str]]:
    """The URDF parsed by ElementTree, its continuous joints made revolute, serialised again."""
    from robocfg.assets.urdf_xml import read_urdf_xml, revolute_continuous

    root = read_urdf_xml(path)
    converted = revolute_continuous(root, math.pi)
    return ET.tostring(root, encoding="unicode"), frozenset(converted)


def _full_model(path: str) -> tuple[pin.Model, frozenset[str]]:
    """pinocchio's model of the whole URDF and the names of its joints made revolute.

    urdfdom (pinocchio's parser) refuses some XML that ElementTree reads and writes back plainly:
    a DOCTYPE with internal entities, a processing instruction inside the document, a tab or line
    break inside a number. A text taken as read that pinocchio refuses is therefore built once more
    from the re-serialised tree, as every file was before the as-read shortcut."""
    xml, continuous = _urdf_xml_without_continuous(path)
    try:
        return pin.buildModelFromXML(xml), continuous
    except ValueError:
        xml2, continuous2 = _reserialised_xml(path)
        if xml2 == xml:
            raise
        return pin.buildModelFromXML(xml2), continuous2


@dataclass
class KinematicModel:
    """A pinocchio model of one arm with everything else locked. Build it with :meth:`from_robot`."""

    model: pin.Model
    data: pin.Data
    joint_names: list[str]
    lower: np.ndarray  # rad or m, arm-joint order
    upper: np.ndarray
    velocity_limits: np.ndarray  # rad/s or m/s
    wrap: np.ndarray  # bool: continuous or ≥ 2π-wide joints (wrapped, not clamped)
    ee_link: str
    home: np.ndarray
    base_pose: np.ndarray  # world_T_base (4x4)
    urdf_path: str = ""
    locked: dict[str, float] = field(default_factory=dict)  # locked joint → value (rad or m)
    default_backend: str = "lm"
    robot: CheckedRobot | None = field(default=None, repr=False)  # source config (collision geometry for IK)
    # bool, arm-joint order: URDF continuous joints. The solvers work in [-π, π] (``lower``/``upper``);
    # ``ik`` then returns each continuous joint at the turn nearest to the seed, unbounded.
    continuous: np.ndarray | None = None
    _solvers: dict[str, IKSolver] = field(default_factory=dict, repr=False)
    _levers: dict[str, tuple[float, ...] | None] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        # OP_FRAME: a URDF link that happens to be called 'tcp' is a BODY frame and stays reachable by type
        self._tcp_id = int(self.model.getFrameId(TCP_FRAME, pin.FrameType.OP_FRAME))
        self._frame_ids: dict[str, int] = {TCP_FRAME: self._tcp_id}
        # fixed after construction (``wrap``/``continuous`` are not changed in place): asked per IK query
        self._any_wrap = bool(self.wrap.any())
        self._any_continuous = self.continuous is not None and bool(self.continuous.any())
        # the limits and the wrap flags as Python lists, for the per-query checks of seeds and answers
        self._limit_lists = (self.lower.tolist(), self.upper.tolist())
        self._wrap_list = self.wrap.tolist()
        self._nq = int(self.model.nq)
        # the joints that are not wrapped (those that can sit at a limit): names, indices, limits
        bounded = [k for k, w in enumerate(self._wrap_list) if not w]
        lo, hi = self._limit_lists
        self._bounded = ([self.joint_names[k] for k in bounded], bounded, [lo[k] for k in bounded], [hi[k] for k in bounded])

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_robot(
        cls,
        robot: CheckedRobot,
        arm: str | None = None,
        base_pose: np.ndarray | None = None,
        gripper_q: dict[str, float] | None = None,
    ) -> KinematicModel:
        """Model of ``arm`` (default: the first) of a checked robot.

        ``base_pose``: 4x4 world_T_base of the URDF root link (the task's mount pose).
        ``gripper_q``: joint name → value for locked joints (default: gripper ``open``,
        other arms at ``home``, anything else 0 clipped into its limits); mimic followers follow
        their leader (``multiplier · q + offset``).

        Each call returns a new model that shares nothing mutable with another: its own pinocchio
        ``Model`` and ``Data``, arrays and solvers. The same arguments give the same model; the
        last few builds are kept (:func:`_remembered`) and copied, since a run builds one twice
        before its first episode (the reach check, then the session).
        """
        key = _build_key(robot, arm, base_pose, gripper_q)
        built = _remembered(key, robot) if key is not None else None
        if built is None:
            built = cls._build(robot, arm, base_pose, gripper_q)
            if key is not None:
                _remember(key, robot, built)
        return built.copy_for(robot)

    def copy_for(self, robot: CheckedRobot | None) -> KinematicModel:
        """A new model equal to this one (a copy of the pinocchio model, new data, no solvers or
        cached lookups yet) whose source config is ``robot``."""
        return type(self)(
            model=pin.Model(self.model), data=self.model.createData(), joint_names=list(self.joint_names),
            lower=self.lower.copy(), upper=self.upper.copy(), velocity_limits=self.velocity_limits.copy(),
            wrap=self.wrap.copy(), ee_link=self.ee_link, home=self.home.copy(), base_pose=self.base_pose.copy(),
            urdf_path=self.urdf_path, locked=dict(self.locked), default_backend=self.default_backend, robot=robot,
            continuous=None if self.continuous is None else self.continuous.copy())

    @classmethod
    def _build(
        cls,
        robot: CheckedRobot,
        arm: str | None,
        base_pose: np.ndarray | None,
        gripper_q: dict[str, float] | None,
    ) -> KinematicModel:
        """The model :meth:`from_robot` describes, built from the URDF."""
        cfg = robot.config
        arm_cfg = cfg.arm(arm)
        full, continuous = _full_model(str(robot.urdf_path))
        arm_joints = robot.arm_joints(arm_cfg)

        locked = locked_joint_values(robot, arm_cfg.name, gripper_q or {})
        q_full = pin.neutral(full)
        lock_ids = []
        for jid in range(1, full.njoints):
            name = full.names[jid]
            if name in arm_joints:
                continue
            lock_ids.append(jid)
            j = full.joints[jid]
            if j.nq != 1:
                raise RobocfgError(f"joint {name!r} has {j.nq} coordinates; only 1-DOF joints can be locked")
            lo, hi = full.lowerPositionLimit[j.idx_q], full.upperPositionLimit[j.idx_q]
            q_full[j.idx_q] = locked[name] if name in locked else float(np.clip(0.0, lo, hi))
        model = pin.buildReducedModel(full, lock_ids, q_full) if lock_ids else full
        names = [model.names[i] for i in range(1, model.njoints)]
        if names != arm_joints:
            raise RobocfgError(f"pinocchio joint order {names} differs from the arm joints {arm_joints}")
        if model.nq != len(arm_joints):
            raise RobocfgError(f"arm joints must be 1-DOF; pinocchio nq = {model.nq} for {len(arm_joints)} joints")

        M_base = pin.SE3.Identity() if base_pose is None else _se3(base_pose, "base_pose")
        for jid in range(1, model.njoints):
            if model.parents[jid] == 0:
                model.jointPlacements[jid] = M_base * model.jointPlacements[jid]
        for fid in range(model.nframes):
            fr = model.frames[fid]
            if fr.parentJoint == 0 and fid != 0:
                fr.placement = M_base * fr.placement
                model.frames[fid] = fr

        ee_id = _frame_id(model, arm_cfg.ee_link)
        ee = model.frames[ee_id]
        offset = np.zeros(3)
        offset[AXIS_INDEX[arm_cfg.ee_axis]] = arm_cfg.tcp_offset
        tcp = pin.Frame(TCP_FRAME, ee.parentJoint, ee_id, ee.placement * pin.SE3(np.eye(3), offset), pin.FrameType.OP_FRAME)
        model.addFrame(tcp)

        lower = np.array(model.lowerPositionLimit, dtype=float)
        upper = np.array(model.upperPositionLimit, dtype=float)
        wrap = np.array([(n in continuous) or (u - lo_ >= 2 * math.pi - 1e-9) for n, lo_, u in zip(arm_joints, lower, upper, strict=True)])
        vel = np.array(model.velocityLimit, dtype=float)
        for k, n in enumerate(arm_joints):
            if n in cfg.drives.velocity_limits:
                vel[k] = cfg.drives.velocity_limits[n]
        return cls(
            model=model,
            data=model.createData(),
            joint_names=list(arm_joints),
            lower=lower,
            upper=upper,
            velocity_limits=vel,
            wrap=wrap,
            ee_link=arm_cfg.ee_link,
            home=np.array(arm_cfg.home, dtype=float),
            base_pose=M_base.homogeneous.copy(),
            urdf_path=str(robot.urdf_path),
            locked={full.names[j]: float(q_full[full.joints[j].idx_q]) for j in lock_ids},
            default_backend=cfg.ik_backend,
            robot=robot,
            continuous=np.array([n in continuous for n in arm_joints], dtype=bool),
        )

    # ------------------------------------------------------------------ queries
    @property
    def nq(self) -> int:
        return self._nq

    @property
    def any_wrap(self) -> bool:
        """True if some joint is continuous or ≥ 2π wide (wrapped instead of clamped)."""
        return self._any_wrap

    @property
    def limit_lists(self) -> tuple[list[float], list[float]]:
        """(lower, upper) limits as Python lists (read only; ``lower``/``upper`` are not changed in place)."""
        return self._limit_lists

    @property
    def bounded(self) -> tuple[list[str], list[int], list[float], list[float]]:
        """The joints that are not wrapped (read only): (names, indices in arm order, lower, upper limits)."""
        return self._bounded

    @property
    def wrap_list(self) -> list[bool]:
        """``wrap`` as a Python list (read only)."""
        return self._wrap_list

    @property
    def mid(self) -> np.ndarray:
        """Midpoint of the joint limits."""
        return (self.lower + self.upper) / 2

    def frame_id(self, frame: str = TCP_FRAME) -> int:
        """pinocchio frame index of ``"tcp"``, ``"ee"`` (the ee_link) or any link name."""
        fid = self._frame_ids.get(frame)
        if fid is None:  # looked up once per name (the model's frames do not change)
            fid = self._frame_ids[frame] = _frame_id(self.model, self.ee_link if frame == "ee" else frame)
        return fid

    def frame_name(self, frame: str = TCP_FRAME) -> str:
        """The pinocchio frame name behind ``frame`` ("ee" → the ee_link)."""
        return self.model.frames[self.frame_id(frame)].name

    def lever_arms(self, frame: str = TCP_FRAME) -> tuple[float, ...] | None:
        """Per joint, a bound (m) on the distance from its axis to ``frame``'s origin at every
        configuration (:func:`robocfg.kinematics.lever_arms.lever_arms`), computed once per frame."""
        if frame not in self._levers:
            from robocfg.kinematics.lever_arms import lever_arms

            self._levers[frame] = lever_arms(self.model, self.frame_id(frame))
        return self._levers[frame]

    def fk(self, q: np.ndarray, frame: str = TCP_FRAME) -> np.ndarray:
        """world_T_frame (4x4) at joint values ``q`` (arm order)."""
        q = self._q(q)
        fid = self.frame_id(frame)
        pin.forwardKinematics(self.model, self.data, q)
        return pin.updateFramePlacement(self.model, self.data, fid).homogeneous.copy()

    def fk_positions(self, qs: np.ndarray, frame: str = TCP_FRAME) -> np.ndarray:
        """World positions (n, 3), m, of ``frame`` at each row of ``qs`` (n, nq): the translations
        of :meth:`fk`, for sampling a path in one call."""
        qs = np.asarray(qs, dtype=float)
        if qs.ndim != 2 or qs.shape[1] != self.nq:
            raise RobocfgError(f"expected rows of {self.nq} joint values ({', '.join(self.joint_names)}), got shape {qs.shape}")
        model, data, fid = self.model, self.data, self.frame_id(frame)
        fk, place = pin.forwardKinematics, pin.updateFramePlacement
        out = np.empty((len(qs), 3))
        for k, q in enumerate(qs):
            fk(model, data, q)
            out[k] = place(model, data, fid).translation
        return out

    def fk_pose_rows(self, qs: np.ndarray, frame: str = TCP_FRAME) -> list[list[list[float]]]:
        """world_T_frame (4 rows of 4 floats; m) at each row of ``qs`` (n, nq): :meth:`fk` for a
        sampled path in one call, as Python floats for per-sample arithmetic (one conversion a
        sample: cheaper than an array filled and converted, or numpy arithmetic on a few rows)."""
        qs = np.asarray(qs, dtype=float)
        if qs.ndim != 2 or qs.shape[1] != self.nq:
            raise RobocfgError(f"expected rows of {self.nq} joint values ({', '.join(self.joint_names)}), got shape {qs.shape}")
        model, data, fid = self.model, self.data, self.frame_id(frame)
        fk, place = pin.forwardKinematics, pin.updateFramePlacement
        out = []
        for q in qs:
            fk(model, data, q)
            out.append(place(model, data, fid).homogeneous.tolist())
        return out

    def jacobian(self, q: np.ndarray, frame: str = TCP_FRAME) -> np.ndarray:
        """(6, nq) Jacobian of ``frame``: rows (v, ω) of the frame origin, world-aligned axes."""
        q = self._q(q)
        fid = self.frame_id(frame)
        return pin.computeFrameJacobian(self.model, self.data, q, fid, pin.LOCAL_WORLD_ALIGNED).copy()

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> bool:
        """True when every joint is within its limits (continuous joints have none)."""
        q = np.asarray(q, dtype=float)
        inside = (q >= self.lower - tol) & (q <= self.upper + tol)
        if self.continuous is not None:
            inside |= self.continuous
        return bool(np.all(inside))

    def ik(
        self,
        target: np.ndarray,
        seed_q: np.ndarray | Sequence[float] | None = None,
        frame: str = TCP_FRAME,
        backend: str | None = None,
        time_budget: float = 0.02,
        position_only: bool = False,
        rng: np.random.Generator | None = None,
    ) -> IKResult:
        """Joint values putting ``frame`` at ``target`` (4x4 world_T_frame).

        ``seed_q`` defaults to the arm's home. ``time_budget`` (s) bounds the search (random
        restarts inside it); ``backend`` defaults to the robot YAML's ``ik_backend``.
        ``rng`` drives the restarts (default: ``default_rng(0)``, so results are reproducible).
        Continuous joints come back at the turn nearest to the seed (outside [-π, π] when it is).
        Never raises for unreachable targets (``converged=False`` with the best residual);
        raises RobocfgError for a NaN/inf or malformed target.
        """
        solver = self.solver(backend)
        seed = self.home if seed_q is None else np.asarray(seed_q, dtype=float)
        res = solver.solve(target, seed_q=seed, frame=frame, time_budget=time_budget, position_only=position_only, rng=rng)
        if self._any_continuous and self.continuous is not None and np.isfinite(seed).all():
            # The same pose with the least travel from the seed: a wrist at π+0.1 stays there, not at −π+0.1.
            turns = np.round((seed - res.q) / (2 * math.pi))
            res.q = np.where(self.continuous, res.q + 2 * math.pi * turns, res.q)
        return res

    def solver(self, backend: str | None = None) -> IKSolver:
        """The (cached) solver instance of ``backend`` (default: the robot YAML's ``ik_backend``),
        e.g. to change its tolerances or its ``clock``."""
        name = backend or self.default_backend
        solver = self._solvers.get(name)
        if solver is None:
            from robocfg.kinematics.ik.registry import get_backend

            solver = self._solvers[name] = get_backend(name)(self)
        return solver

    # ------------------------------------------------------------------ helpers
    def _q(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, dtype=float).reshape(-1)
        if q.shape[0] != self.nq:
            raise RobocfgError(f"expected {self.nq} joint values ({', '.join(self.joint_names)}), got {q.shape[0]}")
        return q


# (key, robot config, parsed URDF, model): the last builds, newest last (see _remembered)
_BUILT: list[tuple[tuple, object, object, KinematicModel]] = []
BUILT_SIZE = 4


def _build_key(robot: CheckedRobot, arm: str | None, base_pose: np.ndarray | None,
               gripper_q: dict[str, float] | None) -> tuple | None:
    """What :meth:`KinematicModel.from_robot` reads besides the robot's config and parsed URDF
    (compared by identity in :func:`_remembered`): the URDF file (path, size, mtime, as the XML is
    remembered), the arm, the base pose's bits and the locked-joint overrides. None (not
    remembered) for a file that cannot be read or a base pose that is not an array of numbers:
    the build reports those."""
    try:
        st = os.stat(robot.urdf_path)
        T = None if base_pose is None else np.asarray(base_pose, dtype=float)
        q = tuple(sorted((str(k), float(v)) for k, v in (gripper_q or {}).items()))
    except (OSError, TypeError, ValueError):
        return None
    pose = None if T is None else (T.shape, T.tobytes())
    return (str(robot.urdf_path), st.st_size, st.st_mtime_ns, arm, pose, q)


def _remembered(key: tuple, robot: CheckedRobot) -> KinematicModel | None:
    """The model built for ``key`` from this very config and parsed URDF (the same objects: a
    frozen config, and the URDF parsed once per checked robot), if it is one of the last few."""
    for k, config, urdf, model in _BUILT:
        if k == key and config is robot.config and urdf is robot.urdf:
            return model
    return None


def _remember(key: tuple, robot: CheckedRobot, model: KinematicModel) -> None:
    if len(_BUILT) >= BUILT_SIZE:
        _BUILT.pop(0)
    _BUILT.append((key, robot.config, robot.urdf, model))


def _se3(T: np.ndarray, what: str) -> pin.SE3:
    T = np.asarray(T, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise RobocfgError(f"{what} must be a finite 4x4 matrix")
    R = T[:3, :3]
    if not np.allclose(R @ R.T, np.eye(3), atol=1e-6) or abs(np.linalg.det(R) - 1) > 1e-6:
        raise RobocfgError(f"{what}: the rotation block is not a rotation matrix")
    return pin.SE3(R.copy(), T[:3, 3].copy())


def _frame_id(model: pin.Model, name: str) -> int:
    if model.existFrame(name, pin.FrameType.BODY):
        return int(model.getFrameId(name, pin.FrameType.BODY))
    if model.existFrame(name):
        return int(model.getFrameId(name))
    known = sorted({f.name for f in model.frames if f.type in (pin.FrameType.BODY, pin.FrameType.OP_FRAME)})
    raise NotFound("frame", name, ["ee", *known])


def locked_joint_values(robot: CheckedRobot, arm_name: str, overrides: dict[str, float]) -> dict[str, float]:
    """Values (rad or m) of every DOF that arm ``arm_name`` does not move: the robot's
    ``locked_joints``, grippers open, other arms at home, ``overrides``, mimic followers following.
    The one source of these values for the kinematic model and the reactive controller."""
    from robocfg.config.robot import ParallelGripperConfig

    values: dict[str, float] = dict(robot.config.locked_joints)
    for a in robot.config.arms:
        if a.name != arm_name:
            values.update(zip(robot.arm_joints(a), a.home, strict=True))
        if isinstance(a.gripper, ParallelGripperConfig):
            values.update(zip(robot.gripper_joints(a), a.gripper.open, strict=True))
    values.update(overrides)
    for j in robot.urdf.joints.values():
        if j.mimic is not None and j.name not in overrides:
            leader = values.get(j.mimic.joint, 0.0)
            values[j.name] = j.mimic.multiplier * leader + j.mimic.offset
    return values
