"""How fast a follow-target motion asks the arm's joints to turn, against their velocity limits.

``placement: auto`` scales a motion written for another robot about the running arm's base and
keeps its times (period, waypoint times, duration): the target goes round at the same angular
speed, so an arm k times bigger moves its TCP k times faster and, being roughly a scaled copy,
turns its joints about as fast as the task's robot did. This module checks that on the arm
itself: along the motion it follows the target by IK (each pose seeded with the previous answer,
the first with home) and maps the target's twist to joint speeds by damped least squares,
``q̇ = Jᵀ(JJᵀ + λ²I)⁻¹·(v, ω)``; the peak of ``|q̇_i| / q̇max_i`` over the samples is the share
of the velocity limits the motion needs. The full twist is used (a roll left free by an
axis-symmetric tool is counted too), so the figure errs high.

Frames: world; m, rad, s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.targets import TargetMotion

SAMPLES = 48  # poses along one period (or the motion's active time)
DAMPING = 1e-3  # λ of the damped least squares (m, rad)
IK_BUDGET = 0.2  # s per IK query (the model's iteration bound decides first)


@dataclass(frozen=True)
class JointSpeed:
    """Peak joint-speed use of a motion: ``share`` = max over samples and joints of |q̇|/q̇max."""

    share: float
    joint: int  # arm-joint index of the peak
    t: float  # s, when (motion time)
    tcp_speed: float  # m/s, peak TCP speed of the target
    samples: int  # poses sampled
    unreached: int  # of them, poses IK did not reach (the figure covers the reached ones)


def sample_times(target: TargetMotion, duration: float) -> np.ndarray:
    """Times (s) covering the motion once: one period of a periodic motion, the waypoints' span, or
    nothing for a static target."""
    m = target.m
    if m.type == "static":
        return np.zeros(0)
    span = m.period if m.type in ("circle", "figure8") else min(duration, float(target.times[-1]) if m.type == "waypoints" else duration)
    return np.linspace(0.0, span, SAMPLES, endpoint=False)


def joint_speed(model: KinematicModel, home: np.ndarray, v_max: np.ndarray, target: TargetMotion,
                times: np.ndarray) -> JointSpeed:
    """Peak share of ``v_max`` (rad/s per arm joint) the joints need to follow ``target`` at ``times``."""
    q = np.asarray(home, float)
    share, joint, when, tcp_speed, unreached = 0.0, 0, 0.0, 0.0, 0
    for t in (float(x) for x in times):
        res = model.ik(target.pose(t), seed_q=q, frame="tcp", time_budget=IK_BUDGET)
        if not res.converged:
            unreached += 1
            continue
        q = res.q
        J = model.jacobian(q, "tcp")
        twist = target.velocity(t)
        dq = J.T @ np.linalg.solve(J @ J.T + DAMPING**2 * np.eye(6), twist)
        use = np.abs(dq) / np.asarray(v_max, float)
        tcp_speed = max(tcp_speed, float(np.linalg.norm(twist[:3])))
        if use.max() > share:
            share, joint, when = float(use.max()), int(np.argmax(use)), t
    return JointSpeed(share, joint, when, tcp_speed, len(times), unreached)


def arm_joint_speed(task: CheckedTask, arm: str | None, target: TargetMotion, duration: float,
                    velocity_scale: float = 1.0) -> JointSpeed:
    """:func:`joint_speed` for the task's robot's ``arm`` (as mounted), against its velocity limits
    (robot YAML, else URDF) × ``velocity_scale``."""
    from robocfg.geometry import pose_matrix
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import bound_ik_by_iterations
    from robocfg.motion.reactive.setup import velocity_limits

    robot = task.robots[0]
    arm_cfg = robot.config.arm(arm)
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=pose_matrix(task.config.robots[0]))
    bound_ik_by_iterations(model)  # same answers whatever the machine load
    v_max = velocity_limits(robot, arm_cfg.name) * velocity_scale
    return joint_speed(model, np.asarray(arm_cfg.home, float), v_max, target, sample_times(target, duration))
