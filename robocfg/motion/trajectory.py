"""Timed joint trajectories: evaluation, sampling, and limit checks.

A trajectory maps time ``t`` (s, from 0 to ``duration``) to joint positions, velocities and
accelerations (rad, rad/s, rad/s²; arrays of shape (N, n) for N times).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robocfg.motion.limits import JointLimits

VIOLATION_TOL = 1e-6  # relative slack when counting limit violations (float round-off)


class Trajectory:
    """Base class: subclasses set ``duration`` and implement ``_eval(t) -> (q, qd, qdd)``."""

    duration: float

    def evaluate(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at times ``t`` (clipped to [0, duration]); shapes (N, n)."""
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration)
        return self._eval(tt)

    def positions_velocities(self, t) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) at times ``t``, the same values as ``evaluate``'s first two; a subclass may skip
        the accelerations (what a played move sends: position and velocity targets)."""
        q, qd, _ = self.evaluate(t)
        return q, qd

    def positions(self, t) -> np.ndarray:
        """q at times ``t``, the same values as ``evaluate``'s first; a subclass may skip the
        derivatives."""
        return self.evaluate(t)[0]

    def step_targets(self, dt: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``positions_velocities`` at the physics steps' times k·``dt`` (s), k = 1 … ``n``: what a
        played move sends (a subclass may use that these times are ascending and positive)."""
        return self.positions_velocities(np.arange(1, n + 1) * dt)

    def _eval(self, t: np.ndarray):  # pragma: no cover - abstract
        raise NotImplementedError

    def sample(self, rate: float) -> SampledTrajectory:
        """Samples every ``1/rate`` s from 0, plus the final time."""
        t = sample_times(self.duration, rate)
        q, qd, qdd = self.evaluate(t)
        return SampledTrajectory(t, q, qd, qdd)


def sample_times(duration: float, rate: float) -> np.ndarray:
    n = int(np.floor(duration * rate + 1e-9))
    t = np.arange(n + 1) / rate
    if duration - t[-1] > 1e-9:
        t = np.append(t, duration)
    return t


class TimeScaled(Trajectory):
    """A toppra-style trajectory ``f`` (callable ``f(t, order)``) slowed down uniformly by ``k`` ≥ 1.

    q(t) = f(t/k), q̇(t) = f'(t/k)/k, q̈(t) = f''(t/k)/k², so velocities scale by 1/k and
    accelerations by 1/k² while the path stays the same.
    """

    def __init__(self, f, duration: float, k: float = 1.0):
        self.f, self.k, self.duration = f, float(k), float(duration) * float(k)

    def _eval(self, t):
        u = np.clip(t / self.k, 0.0, self.duration / self.k)
        return (np.atleast_2d(self.f(u, 0)), np.atleast_2d(self.f(u, 1)) / self.k,
                np.atleast_2d(self.f(u, 2)) / self.k**2)


class Slowed(Trajectory):
    """``inner`` played ``k`` ≥ 1 times slower along the same path: q(t) = inner(t/k), velocities
    scaled by 1/k, accelerations by 1/k²."""

    def __init__(self, inner: Trajectory, k: float):
        self.inner, self.k, self.duration = inner, float(k), float(inner.duration) * float(k)

    def _eval(self, t):
        q, qd, qdd = self.inner.evaluate(t / self.k)
        return q, qd / self.k, qdd / self.k**2


class Piecewise(Trajectory):
    """Consecutive trajectories played one after the other."""

    def __init__(self, parts: list[Trajectory]):
        self.parts = parts
        self.starts = np.concatenate([[0.0], np.cumsum([p.duration for p in parts])])
        self.duration = float(self.starts[-1])

    def _eval(self, t):
        idx = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.parts) - 1)
        out = None
        for i in np.unique(idx):
            sel = idx == i
            vals = self.parts[i].evaluate(t[sel] - self.starts[i])
            if out is None:
                out = [np.zeros((len(t), v.shape[1])) for v in vals]
            for o, v in zip(out, vals, strict=True):
                o[sel] = v
        return tuple(out)


@dataclass
class SampledTrajectory:
    """Samples of a trajectory: ``t`` (N,), ``q``/``qd``/``qdd`` (N, n)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    @property
    def duration(self) -> float:
        return float(self.t[-1])


@dataclass
class LimitCheck:
    """Limit violations counted over samples: each (sample, joint) pair over a limit counts once per
    test (sampled value, finite difference)."""

    rate: float
    samples: int
    position: int
    velocity: int
    acceleration: int
    jerk: int | None
    peak_velocity_ratio: float  # max |q̇| / limit over joints and samples
    peak_acceleration_ratio: float
    peak_jerk_ratio: float | None

    @property
    def total(self) -> int:
        return self.position + self.velocity + self.acceleration + (self.jerk or 0)


def check_limits(traj: Trajectory, limits: JointLimits, rate: float = 1000.0,
                 tol: float = VIOLATION_TOL) -> LimitCheck:
    """Resample ``traj`` at ``rate`` Hz and count samples beyond the limits (relative slack ``tol``).

    Velocity and acceleration are checked twice: the trajectory's own q̇, q̈ at each sample, and
    the finite differences |Δq|/Δt, |Δq̇|/Δt between consecutive samples (by the mean value theorem
    these never exceed the limits either if the limits hold everywhere in between, so they catch
    velocity jumps and excesses between samples). Jerk (when ``limits.jerk`` is set) is the finite
    difference of the sampled accelerations (0.1 % slack).
    """
    s = traj.sample(rate)
    b = limits.bounded()
    span = np.maximum(limits.upper - limits.lower, 1e-9)
    pos = int(np.sum(((s.q < limits.lower - tol * span) | (s.q > limits.upper + tol * span))[:, b]))
    rv = np.abs(s.qd) / limits.velocity
    ra = np.abs(s.qdd) / limits.acceleration
    vel_n, acc_n = int(np.sum(rv > 1 + tol)), int(np.sum(ra > 1 + tol))
    jerk_n, rj = None, None
    if len(s.t) > 2:
        dt = np.diff(s.t)[:, None]
        fv = np.abs(np.diff(s.q, axis=0) / dt) / limits.velocity
        fa = np.abs(np.diff(s.qd, axis=0) / dt) / limits.acceleration
        vel_n += int(np.sum(fv > 1 + tol))
        acc_n += int(np.sum(fa > 1 + tol))
        if limits.jerk is not None:
            jr = np.abs(np.diff(s.qdd, axis=0) / dt) / limits.jerk
            jerk_n, rj = int(np.sum(jr > 1 + 1e-3)), float(jr.max())
    return LimitCheck(rate, len(s.t), pos, vel_n, acc_n, jerk_n, float(rv.max()), float(ra.max()), rj)
