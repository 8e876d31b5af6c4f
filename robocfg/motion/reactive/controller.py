"""Reactive Cartesian controller: one placo QP per control step.

Each step solves for a joint step ``Δq`` (rad) that moves ``ee_link`` towards a servo pose (the
target's feed-forward velocity plus ``gain`` × the error, braked so the approach can stop with
``max_*_acceleration``, speed-capped; a soft frame task),
keeps the arm near its posture (a tiny-weight joints task) with damped least squares (a
regularisation task), respects joint position/velocity/acceleration limits (a hard joint-space box
with braking distance, see :mod:`.limits`), and keeps every robot–environment (and non-adjacent
self) collision pair at least ``margin`` apart with a velocity damper
``n·(J_B − J_A)·Δq ≥ −approach_gain·dt·(d − margin) (− n·v_obstacle·dt)`` — placo half-space rows
filled from coal distances between convex hulls inside ``trigger`` (:mod:`.collision_rows`).

Warm start: the QP is linearised at the previous command (not the noisy measurement), so commands
are continuous; the measured state re-seeds it only after a deviation above ``resync_tolerance``.
Failure handling: an infeasible hard-collision QP is re-solved with soft collision constraints,
and if that fails too the step commands zero velocity. An axis-symmetric tool (``free_roll``) is
servoed to the target turned about its tool axis to the current roll (:mod:`.tool_roll`), so only
where it points is tracked. Frames: world, 4×4 transforms, metres.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.collision.shapes import (
    EnvShape,
    LinkGeometry,
    add_environment,
    add_robot_geometry,
    point_clearance,
    to_convex_hulls,
)
from robocfg.motion.reactive.collision_rows import CollisionRows
from robocfg.motion.reactive.escape import EscapeRule, EscapeSettings
from robocfg.motion.reactive.limits import step_bounds
from robocfg.motion.reactive.placo_urdf import quiet_stdout, urdf_without_geometry
from robocfg.motion.reactive.tool_roll import nearest_roll


@dataclass(frozen=True)
class ArmSpec:
    """What the controller needs to know about one arm (arrays in arm-joint order)."""

    urdf_path: Path
    joint_names: list[str]
    ee_link: str
    T_ee_tcp: np.ndarray  # 4×4, TCP in the ee_link frame
    base_pose: np.ndarray  # 4×4, world pose of the URDF root link
    lower: np.ndarray  # rad; -inf for a continuous joint
    upper: np.ndarray  # rad; +inf for a continuous joint
    velocity_limits: np.ndarray  # rad/s
    acceleration_limits: np.ndarray  # rad/s²
    posture: np.ndarray  # rad, the regularisation target (e.g. home)
    other_joints: dict[str, float] = field(default_factory=dict)  # non-arm DOFs held at these values
    collision: list[LinkGeometry] | None = None  # robot collision geometry; None: placo loads the URDF's
    tool_axis: int = 2  # ee_link axis (0/1/2 = x/y/z) the tool points along (the robot's ee_axis)


@dataclass(frozen=True)
class ReactiveSettings:
    dt: float  # control period (s)
    margin: float = 0.02  # m, safety distance kept from the environment
    trigger: float = 0.12  # m, pairs closer than this enter the QP
    self_trigger: float = 0.05  # m, same for robot self pairs
    approach_gain: float = 10.0  # 1/s: a pair may close at most approach_gain·(d − margin) m/s
    position_weight: float = 1.0
    orientation_weight: float = 1.0
    posture_weight: float = 1e-6
    damping: float = 3e-3  # weight of ‖Δq‖² (damped least squares: no drift or swaying at singularities)
    self_collision: bool = True
    resync_tolerance: float = 0.05  # rad: measured-vs-commanded gap that re-seeds the QP
    gain: float = 20.0  # 1/s: Cartesian servo gain (the QP is asked to close gain·dt of the error)
    max_linear_speed: float = 1.0  # m/s: cap on the commanded TCP speed
    max_angular_speed: float = 2.0  # rad/s
    max_linear_acceleration: float = 2.0  # m/s²: the servo's approach brakes at most this hard
    max_angular_acceleration: float = 5.0  # rad/s²
    free_roll: bool = False  # an axis-symmetric tool (suction cup): the roll about ArmSpec.tool_axis is not tracked
    escape: EscapeSettings = field(default_factory=EscapeSettings)


@dataclass
class StepResult:
    q: np.ndarray  # commanded joint positions (rad)
    dq: np.ndarray  # commanded joint velocities (rad/s)
    status: str  # "ok" | "soft" (collision constraints relaxed) | "fallback" (zero velocity)
    solve_time: float  # s, wall clock of the whole step
    cpu_time: float  # s, CPU time of the whole step (this thread; insensitive to other processes)
    clearance: float  # m, smallest robot–obstacle distance in the model (inf if none)
    escaping: bool  # a via point is being tracked
    blocked: bool  # off target (> 5 mm) with a robot–environment pair within 5 mm of the margin


def _braked(error: np.ndarray, k: float, accel: float, dt: float) -> np.ndarray:
    """The feedback step (m or rad per control period) for ``error``: ``k`` × the error, shortened so
    the speed it asks for can still brake to rest at the target with ``accel`` (m/s² or rad/s²),
    at most ``sqrt(2·accel·|error|)``. Near the target the proportional servo rules; from further
    the approach decelerates as hard as ``accel`` allows instead of stopping within a few periods
    (which the joints' acceleration limits cannot follow, so the QP traded position for it)."""
    e = float(np.linalg.norm(error))
    if e <= 0.0:
        return np.zeros_like(error)
    return error * (min(k * e, math.sqrt(2.0 * accel * e) * dt) / e)


class ReactiveController:
    """Call :meth:`reset` with the start state, then :meth:`step` every ``settings.dt`` seconds."""

    def __init__(self, arm: ArmSpec, env: list[EnvShape], settings: ReactiveSettings):
        import placo

        self.arm, self.s = arm, settings
        if arm.collision is not None:  # kinematics only from the URDF (no mesh loading), our hulls
            self.robot = placo.RobotWrapper(str(arm.urdf_path), placo.Flags.ignore_collisions,
                                            urdf_without_geometry(arm.urdf_path))
            add_robot_geometry(self.robot.collision_model, self.robot.model, arm.collision)
        else:
            with quiet_stdout():
                self.robot = placo.RobotWrapper(str(arm.urdf_path), placo.Flags.ignore_collisions)
        r = self.robot
        r.set_T_world_fbase(np.asarray(arm.base_pose, float))
        for name, value in arm.other_joints.items():
            r.set_joint(name, float(value))
        self.geom = r.collision_model
        self.hulls = to_convex_hulls(self.geom)
        self.n = len(arm.joint_names)
        self.env = {e.name: e for e in env}
        self.env_ids = add_environment(self.geom, env)
        self._q_index = np.array([r.get_joint_offset(j) for j in arm.joint_names])
        self._v_index = np.array([r.get_joint_v_offset(j) for j in arm.joint_names])
        self._set_q(arm.posture)
        self.rows = CollisionRows(r, self.geom, arm, self.env, self.env_ids, settings, self._set_q,
                                  self._q_index, self._v_index)

        s = self.solver = placo.KinematicsSolver(r)
        s.mask_fbase(True)
        for name in r.joint_names():
            if name not in arm.joint_names:
                s.mask_dof(name)
        s.dt = settings.dt
        s.enable_joint_limits(False)  # handled by the box below (with braking distance)
        s.enable_velocity_limits(False)
        self.task = s.add_frame_task(arm.ee_link, np.eye(4))
        self.task.configure("target", "soft", settings.position_weight, settings.orientation_weight)
        self.posture = s.add_joints_task()
        self.posture.set_joints({j: float(v) for j, v in zip(arm.joint_names, arm.posture, strict=True)})
        self.posture.configure("posture", "soft", settings.posture_weight)
        self.regularization = s.add_regularization_task(settings.damping)
        nq = r.model.nq
        A = np.zeros((2 * self.n, nq))
        A[np.arange(self.n), self._q_index] = 1.0
        A[self.n + np.arange(self.n), self._q_index] = -1.0
        self.box = s.add_joint_space_half_spaces_constraint(A, np.zeros(2 * self.n))
        self.box.configure("limits", "hard", 1.0)
        rows = max(len(self.rows.pairs), 1)
        self.collisions = s.add_joint_space_half_spaces_constraint(np.zeros((rows, nq)), np.ones(rows))
        self.collisions.configure("collisions", "hard", 1.0)
        self.escape = EscapeRule(settings.escape, settings.margin)
        env_geoms = list(self.env_ids.values())
        self.escape.clearance_fn = lambda p: point_clearance(self.geom, env_geoms, p)
        self._T_tcp_ee = np.linalg.inv(np.asarray(arm.T_ee_tcp, float))
        self.q = np.asarray(arm.posture, float).copy()
        self.dq = np.zeros(self.n)
        self.t = 0.0
        self.fallbacks = 0
        self.soft_steps = 0

    # -- model ---------------------------------------------------------------------------------
    def _set_q(self, q: np.ndarray) -> None:
        for name, v in zip(self.arm.joint_names, q, strict=True):
            self.robot.set_joint(name, float(v))
        self.robot.update_kinematics()

    def set_obstacle_pose(self, name: str, pose: np.ndarray, velocity: np.ndarray | None = None) -> None:
        """Move environment shape ``name`` to ``pose`` (4×4, world); ``velocity`` (m/s, world) is its
        linear velocity, used so the robot keeps the margin from an approaching obstacle."""
        self.rows.set_obstacle_pose(name, pose, velocity)

    @property
    def pairs(self) -> list[tuple[int, int]]:
        """The watched geometry pairs (indices into the collision model), see :mod:`.collision_rows`."""
        return self.rows.pairs

    def tcp_pose(self, q: np.ndarray | None = None) -> np.ndarray:
        """World TCP pose (4×4) at ``q`` (default: the last command)."""
        if q is not None:
            self._set_q(q)
        return np.asarray(self.robot.get_T_world_frame(self.arm.ee_link)) @ self.arm.T_ee_tcp

    def distances(self) -> list[tuple[str, str, float]]:
        """(robot geometry, environment/robot geometry, distance m) for every pair, at the model state."""
        return self.rows.distances()

    # -- control -------------------------------------------------------------------------------
    def reset(self, q: np.ndarray, dq: np.ndarray | None = None, t: float = 0.0) -> None:
        self.q = np.asarray(q, float).copy()
        self.dq = np.zeros(self.n) if dq is None else np.asarray(dq, float).copy()
        self.t = t
        self.escape.reset()
        self._set_q(self.q)

    def _servo(self, T_tcp: np.ndarray, target: np.ndarray, velocity: np.ndarray | None) -> np.ndarray:
        """The pose to reach this step: feed-forward velocity + ``gain`` × error, speed-capped."""
        import pinocchio as pin

        dt, k = self.s.dt, min(self.s.gain * self.s.dt, 1.0)
        v = np.zeros(6) if velocity is None else np.asarray(velocity, float)
        dp = v[:3] * dt + _braked(target[:3, 3] - T_tcp[:3, 3], k, self.s.max_linear_acceleration, dt)
        n = float(np.linalg.norm(dp))
        if n > self.s.max_linear_speed * dt:
            dp *= self.s.max_linear_speed * dt / n
        dw = v[3:] * dt + _braked(T_tcp[:3, :3] @ pin.log3(T_tcp[:3, :3].T @ target[:3, :3]), k,
                                  self.s.max_angular_acceleration, dt)
        n = float(np.linalg.norm(dw))
        if n > self.s.max_angular_speed * dt:
            dw *= self.s.max_angular_speed * dt / n
        out = np.eye(4)
        out[:3, 3] = T_tcp[:3, 3] + dp
        out[:3, :3] = pin.exp3(dw) @ T_tcp[:3, :3]
        return out

    def step(self, T_target_tcp: np.ndarray, q_measured: np.ndarray | None = None,
             velocity: np.ndarray | None = None) -> StepResult:
        """One control step towards the world TCP pose ``T_target_tcp`` (4×4); ``velocity`` is the
        target's (vx, vy, vz, wx, wy, wz) in m/s and rad/s, world frame, used as feed-forward."""
        t0, c0 = time.perf_counter(), time.thread_time()
        if q_measured is not None and np.max(np.abs(np.asarray(q_measured) - self.q)) > self.s.resync_tolerance:
            self.q = np.asarray(q_measured, float).copy()
            self.dq[:] = 0.0
        self._set_q(self.q)
        self.t += self.s.dt
        blocking, clearance = self.rows.fill(self.collisions.A, self.collisions.b, self.q)
        T_tcp = np.asarray(self.robot.get_T_world_frame(self.arm.ee_link)) @ self.arm.T_ee_tcp
        target = np.asarray(T_target_tcp, float).copy()
        target[:3, 3] = self.escape.update(self.t, T_tcp[:3, 3], target[:3, 3], blocking)
        if self.escape.active:
            velocity = None
        if self.s.free_roll:  # the tool's roll stays where it is: only where it points is servoed
            ax = self.arm.tool_axis
            target[:3, :3] = nearest_roll(target[:3, :3], T_tcp[:3, :3], ax)
            if velocity is not None:
                velocity = np.asarray(velocity, float).copy()
                a = target[:3, ax]
                velocity[3:] -= float(velocity[3:] @ a) * a
        self.task.T_world_frame = self._servo(T_tcp, target, velocity) @ self._T_tcp_ee
        lo, hi = step_bounds(self.q, self.dq, self.arm.lower, self.arm.upper,
                             self.arm.velocity_limits, self.arm.acceleration_limits, self.s.dt)
        b = self.box.b
        b[: self.n] = self.q + hi
        b[self.n :] = -(self.q + lo)
        status = "ok"
        try:
            self.solver.solve(True)
        except RuntimeError:
            status = "soft"
            self._set_q(self.q)
            self.collisions.configure("collisions", "soft", 1e3)
            try:
                self.solver.solve(True)
            except RuntimeError:
                status = "fallback"
            self.collisions.configure("collisions", "hard", 1.0)
        if status == "fallback":
            q_new = self.q.copy()  # hold: zero velocity
            self.fallbacks += 1
        else:
            q_new = np.asarray(self.robot.state.q)[self._q_index].copy()
            self.soft_steps += status == "soft"
        self.dq = (q_new - self.q) / self.s.dt
        self.q = q_new
        off_target = float(np.linalg.norm(T_tcp[:3, 3] - np.asarray(T_target_tcp)[:3, 3])) > 0.005
        blocked = off_target and any(b.distance < self.s.margin + 0.005 for b in blocking)
        return StepResult(self.q.copy(), self.dq.copy(), status, time.perf_counter() - t0, time.thread_time() - c0,
                          clearance, self.escape.active, blocked)
