"""Stop at every waypoint: straight joint-space segments, each a synchronised trapezoid.

This is Isaac Sim's ``to_minimal_time_joint_trajectory`` semantics (the usual baseline): every
segment starts and ends at rest, all joints start and stop together and move along the straight
line between the waypoints. On a straight line from rest to rest, a trapezoidal (or triangular)
profile of the line parameter u ∈ [0, 1] with u̇ ≤ min_i v_i/|Δq_i| and |ü| ≤ min_i a_i/|Δq_i| is
the time-optimal motion, so each segment is optimal on its own.
"""

from __future__ import annotations

import numpy as np

from robocfg.motion.limits import JointLimits
from robocfg.motion.trajectory import Piecewise, Trajectory


class TrapezoidSegment(Trajectory):
    """q(t) = q0 + u(t)·(q1 − q0) with a trapezoidal u(t) from rest to rest."""

    def __init__(self, q0: np.ndarray, q1: np.ndarray, limits: JointLimits):
        self.q0, self.dq = np.asarray(q0, float), np.asarray(q1, float) - np.asarray(q0, float)
        moving = np.abs(self.dq) > 0
        if not moving.any():
            self.V = self.A = 1.0
            self.t1 = self.t2 = self.duration = 0.0
            return
        V = float(np.min(limits.velocity[moving] / np.abs(self.dq[moving])))
        A = float(np.min(limits.acceleration[moving] / np.abs(self.dq[moving])))
        if V * V / A >= 1.0:  # triangle: never reaches V
            V = float(np.sqrt(A))
            self.t1 = self.t2 = V / A
        else:
            self.t1 = V / A
            self.t2 = 1.0 / V  # start of deceleration: t1 + (1 - V·t1)/V
        self.V, self.A = V, A
        self.duration = self.t2 + self.t1

    def _eval(self, t):
        V, A, t1, t2, T = self.V, self.A, self.t1, self.t2, self.duration
        u = np.where(t < t1, 0.5 * A * t**2,
                     np.where(t < t2, 0.5 * A * t1**2 + V * (t - t1), 1.0 - 0.5 * A * (T - t) ** 2))
        ud = np.where(t < t1, A * t, np.where(t < t2, V, A * (T - t)))
        udd = np.where(t < t1, A, np.where(t < t2, 0.0, -A))
        if T == 0.0:
            u, ud, udd = np.ones_like(t), np.zeros_like(t), np.zeros_like(t)
        return (self.q0 + u[:, None] * self.dq, ud[:, None] * self.dq, udd[:, None] * self.dq)


def stop_at_waypoints(waypoints: np.ndarray, limits: JointLimits) -> Piecewise:
    """One synchronised trapezoid per segment, at rest at every waypoint."""
    W = np.asarray(waypoints, dtype=float)
    return Piecewise([TrapezoidSegment(W[i], W[i + 1], limits) for i in range(len(W) - 1)])
