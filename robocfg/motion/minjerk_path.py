"""Fast rest-to-rest timing of a joint path: a cubic spline through the waypoints, traversed with
a minimum-jerk time law s(τ) = 10τ³ − 15τ⁴ + 6τ⁵.

Not time-optimal (toppra is, see :mod:`robocfg.motion.timing`), but it costs ~0.1 ms instead of
10–30 ms, which matters for controllers that plan every phase of every episode (pick-place). The
duration is the smallest one for which the sampled joint velocities and accelerations stay within
the limits (a bound that is tight at the peak of the time law). Units: rad, s.
"""

from __future__ import annotations

import numpy as np

from robocfg.motion.cubic import CubicSpline  # scipy's bits without importing scipy.interpolate
from robocfg.motion.limits import JointLimits
from robocfg.motion.trajectory import Trajectory

PEAK_SPEED = 1.875  # max ds/dτ of the min-jerk law
PEAK_ACCEL = 5.7735  # max |d²s/dτ²| of the min-jerk law
SAMPLES = 64


class _Segment:
    """The straight joint path W0 + s·(W1 − W0), s ∈ [0, 1], called like a ``CubicSpline``:
    ``path(s, order)``. Bit for bit what ``CubicSpline`` gives for two waypoints clamped to the
    chord's slope (its cubic and quadratic coefficients are exactly 0), without building one."""

    def __init__(self, W: np.ndarray):
        self.start, self.delta = W[0], W[1] - W[0]

    def __call__(self, s, order: int = 0) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        if order == 0:
            return s[..., None] * self.delta + self.start
        if order == 1:
            return np.broadcast_to(self.delta, (*s.shape, len(self.delta))).copy()
        return np.zeros((*s.shape, len(self.delta)))

    def derivatives(self, s, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[self(s, nu) for nu in nus]`` (the interface of :meth:`CubicSpline.derivatives`)."""
        return [self(s, nu) for nu in nus]


class MinJerkPath(Trajectory):
    """q(t) = spline(s(t / T)), rest to rest, through ``waypoints`` (k, n) with k ≥ 2 (two: the
    straight segment, no spline built)."""

    def __init__(self, waypoints: np.ndarray, limits: JointLimits, min_duration: float = 0.05):
        W = np.array(waypoints, dtype=float)  # a copy: the path keeps its own waypoints
        seg = np.linalg.norm(np.diff(W, axis=0), axis=1)
        moved = seg > 1e-9
        if len(W) < 2 or not moved.all():  # repeated waypoints dropped (else W and seg stay as they are)
            W = W[np.concatenate([[True], moved])]
            if len(W) < 2:
                W = np.vstack([W, W])
                seg = np.array([1.0])
            else:
                seg = np.linalg.norm(np.diff(W, axis=0), axis=1)
        self.waypoints = W
        self.spline: _Segment | CubicSpline
        if len(W) == 2:  # a straight segment: linear in s
            self.spline = _Segment(W)
            d1, d2 = np.abs(W[1] - W[0]), np.zeros(W.shape[1])
        else:
            knots = np.concatenate([[0.0], np.cumsum(seg)])
            knots /= knots[-1]
            self.spline = CubicSpline(knots, W, axis=0, bc_type="not-a-knot" if len(W) > 3 else "natural")
            s = np.linspace(0.0, 1.0, SAMPLES)
            v1, v2 = self.spline.derivatives(s, (1, 2))
            d1, d2 = np.abs(v1).max(axis=0), np.abs(v2).max(axis=0)
        t_vel = PEAK_SPEED * np.max(d1 / limits.velocity)
        t_acc = np.sqrt(np.max((d2 * PEAK_SPEED**2 + d1 * PEAK_ACCEL) / limits.acceleration))
        self.duration = float(max(t_vel, t_acc, min_duration))

    def positions_velocities(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``evaluate(t)``'s (q, qd) by the same arithmetic, without the accelerations. A spline's
        are evaluated a joint at a time along the times (:meth:`CubicSpline.derivatives_by_column`)
        and come back as the transposes of those (n, N) arrays (the same values; not C-ordered)."""
        tau, s = self._law(t)
        sd = 30 * tau**2 * (1 - tau) ** 2 / self.duration
        if isinstance(self.spline, CubicSpline) and s.ndim == 1:
            q, d1 = self.spline.derivatives_by_column(s, (0, 1))
            d1 *= sd  # d1 is new: scaled in place, each element as d1 * sd[:, None] scales it
            return q.T, d1.T
        q, d1 = self.spline.derivatives(s, (0, 1))
        return q, d1 * sd[:, None]

    def positions(self, t) -> np.ndarray:
        """``evaluate(t)``'s q by the same arithmetic (C-ordered), without the derivatives."""
        _, s = self._law(t)
        if isinstance(self.spline, CubicSpline) and s.ndim == 1:
            return np.ascontiguousarray(self.spline.derivatives_by_column(s, (0,))[0].T)
        return self.spline.derivatives(s, (0,))[0]

    def _law(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(τ, s) of the min-jerk law at times ``t`` (s; clipped to [0, duration]), as ``_eval``
        computes them."""
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        tau = np.clip(tt / self.duration, 0.0, 1.0)
        return tau, tau**3 * (10 - 15 * tau + 6 * tau**2)

    def _eval(self, t):
        T = self.duration
        tau = np.clip(t / T, 0.0, 1.0)
        s = tau**3 * (10 - 15 * tau + 6 * tau**2)
        sd = 30 * tau**2 * (1 - tau) ** 2 / T
        sdd = 60 * tau * (1 - tau) * (1 - 2 * tau) / T**2
        q, d1, d2 = self.spline.derivatives(s, (0, 1, 2))
        return q, d1 * sd[:, None], d2 * sd[:, None] ** 2 + d1 * sdd[:, None]
