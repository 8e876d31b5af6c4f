"""A loaded robot in a PyBullet world, read and written by joint and link *name*.

Index spaces (mapped once, in ``__init__``):

* joint name → PyBullet joint index (``getJointInfo`` order, fixed joints included);
* joint name → DOF index (position among the movable joints, the order ``robocfg inspect`` prints);
* link name → PyBullet link index (a link's index is that of the joint above it; the root is −1).

Position drives (``command_positions``): PyBullet's ``POSITION_CONTROL`` motor minimises
``positionGain·(q* − q) + velocityGain·(q̇* − q̇)`` as a velocity-level constraint row capped at
``force``. The robot YAML's ``drives.arm`` maps as ``stiffness → positionGain`` (dimensionless,
≈ the fraction of the position error removed per step, 0.01–1), ``damping → velocityGain``
(dimensionless, 1.0 = fully track the target velocity) and ``max_force → force`` (N·m for
revolute, N for prismatic joints). These are *not* PhysX stiffness/damping in N·m/rad.

Length (≈ 300 lines): one concept, the robot's name-to-index maps and everything that reads or
writes through them (joints, drives, link poses, self-collision query); ``ArmHandle`` is a thin
view of one arm over the same maps. Splitting it would pass the maps around for no gain.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pybullet as p

from robocfg.checks.robot import CheckedRobot
from robocfg.config.robot import ArmConfig, DriveGains
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import NotFound
from robocfg.geometry import pose_to_matrix

if TYPE_CHECKING:
    from robocfg.sim.gripper.base import Gripper
    from robocfg.sim.mimic import MimicGears

MOVABLE_TYPES = (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC)
# (token, joint indices, position gains, velocity gains, forces, drives): see RobotHandle.motor_plan
MotorPlan = tuple[object, list[int], list[float], list[float], list[float], list["Drive"]]


@dataclass
class Drive:
    """The position target a joint is held at, with its motor settings."""

    target: float
    position_gain: float
    velocity_gain: float
    force: float
    target_velocity: float = 0.0
    max_velocity: float | None = None


class RobotHandle:
    """One robot body: name ↔ index maps, state by name, position drives, arms."""

    def __init__(self, client: int, body_id: int, checked: CheckedRobot):
        self.client, self.body_id, self.checked = client, body_id, checked
        self.config = checked.config
        self.name = checked.config.name
        self.joint_index: dict[str, int] = {}
        self.link_index: dict[str, int] = {}
        self.joint_types: dict[str, int] = {}
        self.joint_limits: dict[str, tuple[float, float]] = {}
        root = p.getBodyInfo(body_id, physicsClientId=client)[0].decode()
        self.link_index[root] = -1
        self.root_link = root
        for i in range(p.getNumJoints(body_id, physicsClientId=client)):
            info = p.getJointInfo(body_id, i, physicsClientId=client)
            jname, lname = info[1].decode(), info[12].decode()
            self.joint_index[jname] = i
            self.link_index[lname] = i
            self.joint_types[jname] = info[2]
            self.joint_limits[jname] = (info[8], info[9])
        self.movable_joints = [n for n, i in self.joint_index.items() if self.joint_types[n] in MOVABLE_TYPES]
        self.dof_index = {n: k for k, n in enumerate(self.movable_joints)}
        self._movable_indices = [self.joint_index[n] for n in self.movable_joints]
        self.drives: dict[str, Drive] = {}
        self._fast: dict[tuple[str, ...], MotorPlan] = {}
        self._drive_tokens: dict[tuple[str, ...], object] = {}
        self.mimic: MimicGears | None = None  # set by the World
        self.arms: dict[str, ArmHandle] = {a.name: ArmHandle(self, a) for a in self.config.arms}

    # ---- name lookups -------------------------------------------------------------------
    def joint_indices(self, names: Sequence[str]) -> list[int]:
        """PyBullet joint indices of ``names`` (NotFound lists the joints that exist)."""
        try:
            return [self.joint_index[n] for n in names]
        except KeyError as exc:
            raise NotFound("joint", str(exc.args[0]), list(self.joint_index)) from None

    def link(self, name: str) -> int:
        """PyBullet link index of ``name`` (−1 for the root link)."""
        try:
            return self.link_index[name]
        except KeyError:
            raise NotFound("link", name, list(self.link_index)) from None

    def link_name(self, index: int) -> str:
        for n, i in self.link_index.items():
            if i == index:
                return n
        return f"#{index}"

    # ---- state --------------------------------------------------------------------------
    def joint_positions(self, names: Sequence[str] | None = None) -> np.ndarray:
        """Joint positions (rad or m) of ``names`` (default: all movable joints, DOF order)."""
        idx = self.joint_indices(self.movable_joints if names is None else names)
        states = p.getJointStates(self.body_id, idx, physicsClientId=self.client)
        return np.array([s[0] for s in states], dtype=float)

    def joint_velocities(self, names: Sequence[str] | None = None) -> np.ndarray:
        """Joint velocities (rad/s or m/s) of ``names`` (default: all movable joints)."""
        idx = self.joint_indices(self.movable_joints if names is None else names)
        states = p.getJointStates(self.body_id, idx, physicsClientId=self.client)
        return np.array([s[1] for s in states], dtype=float)

    def joint_states(self, names: Sequence[str]) -> tuple[list[float], list[float]]:
        """(positions, velocities) of ``names`` from one state read, as plain lists (rad or m, rad/s
        or m/s): for per-frame sampling, no arrays built."""
        states = p.getJointStates(self.body_id, self.joint_indices(names), physicsClientId=self.client)
        return [s[0] for s in states], [s[1] for s in states]

    def reset_joints(self, names: Sequence[str], q: Sequence[float] | np.ndarray, hold: bool = True) -> None:
        """Teleport joints to ``q`` (zero velocity) and, if ``hold``, keep their drives there."""
        for n, i, v in zip(names, self.joint_indices(names), np.asarray(q, dtype=float), strict=True):
            p.resetJointState(self.body_id, i, float(v), 0.0, physicsClientId=self.client)
            if hold and n in self.drives:
                self.drives[n].target = float(v)
                self.drives[n].target_velocity = 0.0
        if hold:
            self._send([n for n in names if n in self.drives])

    def command_positions(
        self,
        names: Sequence[str],
        q: Sequence[float] | np.ndarray,
        velocities: Sequence[float] | np.ndarray | None = None,
        gains: DriveGains | None = None,
        forces: Sequence[float] | np.ndarray | None = None,
    ) -> None:
        """Drive ``names`` towards ``q`` (POSITION_CONTROL; non-blocking: ``world.step`` moves them).

        ``velocities`` are target joint velocities (feed-forward, default 0). ``gains`` default to
        the drive's current gains (the robot YAML's ``drives.arm`` for joints without a drive yet).
        """
        if gains is None and forces is None and self._command_fast(names, q, velocities):
            return
        g = gains or self.config.drives.arm
        qd = np.zeros(len(names)) if velocities is None else np.asarray(velocities, dtype=float)
        for k, (n, v) in enumerate(zip(names, np.asarray(q, dtype=float), strict=True)):
            d = self.drives.get(n)
            if d is None or gains is not None:
                d = self.drives[n] = Drive(float(v), g.stiffness, g.damping, g.max_force)
                self._drive_tokens.clear()
            d.target, d.target_velocity = float(v), float(qd[k])
            if forces is not None:
                d.force = float(forces[k])
                self._drive_tokens.clear()
        self._send(list(names))

    def _command_fast(self, names: Sequence[str], q: Sequence[float] | np.ndarray, velocities: Sequence[float] | np.ndarray | None) -> bool:
        """The per-step path: one motor call with gains cached per joint list. False → slow path
        (a joint without a drive yet, or with a speed cap)."""
        plan = self.motor_plan(tuple(names))
        if plan is None:
            return False
        _, idx, kp, kd, force, drives = plan
        # lists (a trajectory converted once) are sent as they are: no per-step array round trip
        targets = q if type(q) is list else np.asarray(q, dtype=float).tolist()
        if velocities is None:
            speeds = [0.0] * len(idx)
        else:
            speeds = velocities if type(velocities) is list else np.asarray(velocities, dtype=float).tolist()
        if len(targets) != len(idx) or len(speeds) != len(idx):
            return False
        for d, v, w in zip(drives, targets, speeds):  # noqa: B905 - lengths checked above
            d.target, d.target_velocity = v, w
        p.setJointMotorControlArray(self.body_id, idx, p.POSITION_CONTROL, targetPositions=targets,
                                    targetVelocities=speeds, positionGains=kp, velocityGains=kd, forces=force,
                                    physicsClientId=self.client)
        return True

    def motor_plan(self, key: tuple[str, ...]) -> MotorPlan | None:
        """The cached motor settings of joints ``key`` for one ``setJointMotorControlArray`` call:
        (token, PyBullet joint indices, position gains, velocity gains, forces, drives), valid while
        ``token is self.drive_token(key)`` (a drive of ``key`` replaced: a new token). None when a
        joint has no drive yet or a speed cap (those go through ``setJointMotorControl2``)."""
        plan = self._fast.get(key)
        if plan is None or plan[0] is not self._drive_list(key):
            maybe = [self.drives.get(n) for n in key]
            drives = [d for d in maybe if d is not None]
            if len(drives) < len(maybe) or any(d.max_velocity is not None for d in drives):
                return None
            plan = self._fast[key] = (
                self._drive_list(key), [self.joint_index[n] for n in key], [d.position_gain for d in drives],
                [d.velocity_gain for d in drives], [d.force for d in drives], drives)
        return plan

    def drive_token(self, key: tuple[str, ...]) -> object | None:
        """The current token of joints ``key`` (None: some drive was replaced since the last plan)."""
        return self._drive_tokens.get(key)

    def _drive_list(self, key: tuple[str, ...]) -> object:
        """A token that changes whenever a drive of ``key`` is replaced (the fast path's cache key)."""
        token = self._drive_tokens.get(key)
        if token is None:  # (setdefault would make a new object every step)
            token = self._drive_tokens[key] = object()
        return token

    def set_drive(self, name: str, drive: Drive) -> None:
        """Install a drive with explicit settings (used by grippers) and send it."""
        self.drives[name] = drive
        self._drive_tokens.clear()
        self._send([name])

    def release_joints(self, names: Sequence[str]) -> None:
        """Switch the motors of ``names`` off (zero-force velocity control), e.g. mimic followers."""
        self._drive_tokens.clear()
        for n in names:
            self.drives.pop(n, None)
            p.setJointMotorControl2(self.body_id, self.joint_index[n], p.VELOCITY_CONTROL, force=0.0,
                                    physicsClientId=self.client)

    def _send(self, names: Sequence[str]) -> None:
        if not names:
            return
        limited = [n for n in names if self.drives[n].max_velocity is not None]
        for n in limited:
            d = self.drives[n]
            p.setJointMotorControl2(self.body_id, self.joint_index[n], p.POSITION_CONTROL,
                                    targetPosition=d.target, targetVelocity=d.target_velocity,
                                    positionGain=d.position_gain, velocityGain=d.velocity_gain,
                                    force=d.force, maxVelocity=d.max_velocity, physicsClientId=self.client)
        rest = [n for n in names if self.drives[n].max_velocity is None]
        if rest:
            ds = [self.drives[n] for n in rest]
            p.setJointMotorControlArray(
                self.body_id, self.joint_indices(rest), p.POSITION_CONTROL,
                targetPositions=[d.target for d in ds], targetVelocities=[d.target_velocity for d in ds],
                positionGains=[d.position_gain for d in ds], velocityGains=[d.velocity_gain for d in ds],
                forces=[d.force for d in ds], physicsClientId=self.client)

    # ---- frames -------------------------------------------------------------------------
    def link_pose(self, link: str) -> np.ndarray:
        """4x4 pose of the URDF frame of ``link`` in the world (not its centre of mass)."""
        i = self.link(link)
        if i == -1:
            return self.base_pose()
        s = p.getLinkState(self.body_id, i, computeForwardKinematics=True, physicsClientId=self.client)
        return pose_to_matrix(s[4], s[5])

    def link_position_quat(self, link: str) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(position m, quaternion x y z w) of the URDF frame of ``link`` in the world, as PyBullet
        gives them: no matrix built, for per-frame sampling (the root link: its base pose)."""
        i = self.link(link)
        if i == -1:
            from robocfg.geometry.pose import matrix_to_pose

            pos, quat = matrix_to_pose(self.base_pose())
            return tuple(pos), tuple(quat)
        s = p.getLinkState(self.body_id, i, computeForwardKinematics=True, physicsClientId=self.client)
        return s[4], s[5]

    def base_pose(self) -> np.ndarray:
        """4x4 world pose of the root link's URDF frame."""
        pos, orn = p.getBasePositionAndOrientation(self.body_id, physicsClientId=self.client)
        T_com = pose_to_matrix(pos, orn)
        dyn = p.getDynamicsInfo(self.body_id, -1, physicsClientId=self.client)
        T_inertial = pose_to_matrix(dyn[3], dyn[4])
        return T_com @ np.linalg.inv(T_inertial)

    def arm(self, name: str | None = None) -> ArmHandle:
        """The named arm (default: the first one)."""
        if name is None:
            return next(iter(self.arms.values()))
        if name not in self.arms:
            raise NotFound("arm", name, list(self.arms))
        return self.arms[name]

    def self_collisions(self) -> list[tuple[str, str, float]]:
        """Pairs of this robot's links in contact now: (link A, link B, penetration depth m ≤ 0)."""
        p.performCollisionDetection(physicsClientId=self.client)
        out: dict[tuple[str, str], float] = {}
        for c in p.getContactPoints(self.body_id, self.body_id, physicsClientId=self.client):
            a, b = sorted((self.link_name(c[3]), self.link_name(c[4])))
            out[(a, b)] = min(out.get((a, b), 0.0), c[8])
        return [(a, b, d) for (a, b), d in sorted(out.items())]


@dataclass
class ArmHandle:
    """One arm of a robot: its config, joint names, home, gripper and TCP."""

    robot: RobotHandle
    config: ArmConfig
    joints: list[str] = field(init=False)
    home: np.ndarray = field(init=False)
    gripper: Gripper | None = None  # set by the World

    def __post_init__(self) -> None:
        self.joints = self.robot.checked.arm_joints(self.config)
        self.home = np.asarray(self.config.home, dtype=float)

    def joint_positions(self) -> np.ndarray:
        return self.robot.joint_positions(self.joints)

    def require_gripper(self) -> Gripper:
        """The arm's gripper; ``RobocfgError`` naming the arm when it has none."""
        if self.gripper is None:
            from robocfg.errors import RobocfgError

            raise RobocfgError(f"arm {self.config.name!r} of robot {self.robot.name!r} has no gripper")
        return self.gripper

    def command(self, q: Sequence[float] | np.ndarray, velocities: Sequence[float] | np.ndarray | None = None) -> None:
        """Drive the arm joints to ``q`` (rad) with the robot YAML's arm gains."""
        self.robot.command_positions(self.joints, q, velocities)

    def ee_pose(self) -> np.ndarray:
        """4x4 world pose of ``ee_link``."""
        return self.robot.link_pose(self.config.ee_link)

    def ee_position_quat(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """(position m, quaternion x y z w) of ``ee_link`` in the world, as PyBullet gives them
        (what :meth:`ee_pose` is built from, no matrix made)."""
        return self.robot.link_position_quat(self.config.ee_link)

    def tcp_pose(self) -> np.ndarray:
        """4x4 world pose of the TCP: ``ee_link`` shifted by ``tcp_offset`` along its ``ee_axis``."""
        T = self.ee_pose()
        T_off = np.eye(4)
        T_off[AXIS_INDEX[self.config.ee_axis], 3] = self.config.tcp_offset
        return T @ T_off
