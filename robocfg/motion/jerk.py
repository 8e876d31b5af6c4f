"""Jerk-limited motion through waypoints with ruckig (Berscheid & Kröger 2021), used only when the
task gives a jerk limit.

The community ruckig computes time-optimal state-to-state motions. Through waypoints we chain
one such motion per segment: each waypoint is passed with the velocity the time-optimal toppra
trajectory has there (zero with ``stop_at_waypoints``) and zero acceleration. Between waypoints
the motion is ruckig's own (synchronised per segment), not the spline, so it is not the global
optimum; it stays within the velocity, acceleration and jerk limits, and within the joint
limits (ruckig's position limits; a segment that cannot respect them stops at its waypoint).
"""

from __future__ import annotations

import numpy as np

from robocfg.errors import RunFailed
from robocfg.motion.limits import JointLimits
from robocfg.motion.trajectory import Piecewise, Trajectory


class RuckigSegment(Trajectory):
    """One ruckig trajectory (state to state)."""

    def __init__(self, traj):
        self.traj, self.duration = traj, float(traj.duration)

    def _eval(self, t):
        out = [self.traj.at_time(float(ti)) for ti in t]
        return tuple(np.array([o[k] for o in out], dtype=float) for k in range(3))


def _segment(q0, v0, q1, v1, limits: JointLimits):
    import ruckig

    n = limits.dof
    otg = ruckig.Ruckig(n)
    inp = ruckig.InputParameter(n)
    inp.current_position, inp.current_velocity, inp.current_acceleration = list(q0), list(v0), [0.0] * n
    inp.target_position, inp.target_velocity, inp.target_acceleration = list(q1), list(v1), [0.0] * n
    inp.max_velocity, inp.max_acceleration = list(limits.velocity), list(limits.acceleration)
    inp.max_jerk = list(limits.jerk)  # type: ignore[arg-type]
    b = limits.bounded()
    inp.max_position = [float(u) if bb else 1e9 for u, bb in zip(limits.upper, b, strict=True)]
    inp.min_position = [float(lo) if bb else -1e9 for lo, bb in zip(limits.lower, b, strict=True)]
    traj = ruckig.Trajectory(n)
    try:
        res = otg.calculate(inp, traj)
    except RuntimeError:
        return None
    return traj if res in (ruckig.Result.Working, ruckig.Result.Finished) else None


def jerk_limited(waypoints: np.ndarray, velocities: np.ndarray, limits: JointLimits) -> Piecewise:
    """Chain ruckig segments through ``waypoints`` (k, n) passing them at ``velocities`` (k, n).

    A segment that fails with the given pass-through velocities is retried ending at rest.
    """
    if limits.jerk is None:
        raise ValueError("jerk_limited needs limits.jerk")
    W, Vw = np.asarray(waypoints, float), np.array(velocities, float)
    Vw[0] = Vw[-1] = 0.0
    Vw = np.clip(Vw, -limits.velocity, limits.velocity)
    parts: list[Trajectory] = []
    for i in range(len(W) - 1):
        traj = _segment(W[i], Vw[i], W[i + 1], Vw[i + 1], limits)
        if traj is None:
            Vw[i + 1] = 0.0
            traj = _segment(W[i], Vw[i], W[i + 1], Vw[i + 1], limits)
        if traj is None:
            raise RunFailed("timing", f"ruckig found no jerk-limited motion from waypoint {i} to {i + 1}")
        parts.append(RuckigSegment(traj))
    return Piecewise(parts)
