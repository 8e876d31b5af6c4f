"""Fast rest-to-rest timing of a joint path: a cubic spline through the waypoints, traversed with
a minimum-jerk time law s(τ) = 10τ³ − 15τ⁴ + 6τ⁵.

Not time-optimal (toppra is, see :mod:`robocfg.motion.timing`), but it costs ~0.1 ms instead of
10–30 ms, which matters for controllers that plan every phase of every episode (pick-place). The
duration is the smallest one for which the joint velocities and accelerations stay within the
limits by a bound from the path's exact derivative maxima (tight at the peak of the time law).
Units: rad, s.
"""

from __future__ import annotations

import math
from itertools import pairwise

import numpy as np

from robocfg.motion.cubic import CubicSpline  # scipy's bits without importing scipy.interpolate
from robocfg.motion.limits import JointLimits
from robocfg.motion.trajectory import Trajectory

PEAK_SPEED = 1.875  # max ds/dτ of the min-jerk law
PEAK_ACCEL = 5.7735  # max |d²s/dτ²| of the min-jerk law


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

    def derivatives_by_column(self, s, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[self(s, nu).T for nu in nus]`` for 1-D ``s``: (n, len(s)) arrays, the same values
        (the interface of :meth:`CubicSpline.derivatives_by_column`)."""
        s = np.asarray(s, dtype=float)
        if s.ndim != 1:
            raise ValueError("derivatives_by_column: 1-D s only")
        out = []
        for nu in nus:
            if nu == 0:
                out.append(self.delta[:, None] * s + self.start[:, None])
            elif nu == 1:
                out.append(np.repeat(self.delta[:, None], len(s), axis=1))
            else:
                out.append(np.zeros((len(self.delta), len(s))))
        return out


class _Cubic:
    """The one polynomial of degree ≤ 3 through three or four waypoints at knots ``x`` (0 … 1):
    what scipy's not-a-knot ``CubicSpline`` is for so few points (its interior knots are not
    knots), from Newton's divided differences, without the banded solve. ``c`` (4, 1, n) and
    ``x`` = [0, 1] in ``CubicSpline``'s layout (highest power first), one piece; ``path(s, order)``
    by Horner's rule."""

    def __init__(self, x: list[float], W: list[list[float]]):
        # Python floats, a joint at a time: each difference, quotient and product the one the
        # elementwise numpy version makes (the same bits), without a dozen small-array calls
        x1, x2 = x[1], x[2] if len(W) == 4 else 0.0  # x[0] = 0
        c3, c2, c1 = [], [], []
        for j, w0 in enumerate(W[0]):
            f01 = (W[1][j] - w0) / (x[1] - x[0])
            f12 = (W[2][j] - W[1][j]) / (x[2] - x[1])
            f012 = (f12 - f01) / (x[2] - x[0])
            if len(W) == 4:
                f23 = (W[3][j] - W[2][j]) / (x[3] - x[2])
                f0123 = ((f23 - f12) / (x[3] - x[1]) - f012) / (x[3] - x[0])
            else:
                f0123 = 0.0
            # W0 + f01·s + f012·s(s − x1) + f0123·s(s − x1)(s − x2), in powers of s
            c3.append(f0123)
            c2.append(f012 - f0123 * (x1 + x2))
            c1.append(f01 - f012 * x1 + f0123 * x1 * x2)
        self.c = np.array([c3, c2, c1, W[0]])[:, None, :]
        self.x = np.array([0.0, 1.0])

    def __call__(self, s, order: int = 0) -> np.ndarray:
        return self.derivatives(s, (order,))[0]

    def derivatives(self, s, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[path(s, nu) for nu in nus]`` (the interface of :meth:`CubicSpline.derivatives`)."""
        s = np.asarray(s, dtype=float)[..., None]
        coef = tuple(self.c[:, 0])
        return [_horner(coef, s, nu, s.shape[:-1] + coef[0].shape) for nu in nus]

    def derivatives_by_column(self, s, nus: tuple[int, ...]) -> list[np.ndarray]:
        """``[path(s, nu).T for nu in nus]`` for 1-D ``s``: (n, len(s)) arrays, the same values
        (each element the same operations as :meth:`derivatives`; the interface of
        :meth:`CubicSpline.derivatives_by_column`)."""
        s = np.asarray(s, dtype=float)
        if s.ndim != 1:
            raise ValueError("derivatives_by_column: 1-D s only")
        coef = tuple(v[:, None] for v in self.c[:, 0])
        return [_horner(coef, s, nu, (len(coef[0]), len(s))) for nu in nus]


def _horner(coef: tuple[np.ndarray, ...], s: np.ndarray, nu: int, shape: tuple[int, ...]) -> np.ndarray:
    """The ``nu``-th derivative of a·s³ + b·s² + c·s + d (``coef`` = (a, b, c, d), broadcast
    against ``s``) by Horner's rule; ``shape``: the result's, for the constant derivatives."""
    a, b, c, d = coef
    if nu == 0:  # ((a·s + b)·s + c)·s + d, in place in the first product (of the full shape): the same operations
        r = a * s
        r += b
        r *= s
        r += c
        r *= s
        r += d
        return r
    if nu == 1:  # (3a·s + 2b)·s + c, likewise
        r = 3 * a * s
        r += 2 * b
        r *= s
        r += c
        return r
    if nu == 2:
        return 6 * a * s + 2 * b
    return np.broadcast_to(6 * a if nu == 3 else 0 * a, shape).copy()


JointSpline = _Segment | _Cubic | CubicSpline


def joint_path(waypoints: np.ndarray) -> tuple[np.ndarray, JointSpline]:
    """The geometric joint path a :class:`MinJerkPath` through ``waypoints`` (k, n) plays:
    ``(kept waypoints, path)`` with ``path(s, order)`` for s ∈ [0, 1] (chord-length knots in joint
    space). Repeated waypoints are dropped; two left: the straight segment (no spline built);
    three or four: the one polynomial through them (scipy's not-a-knot spline for so few points);
    more: a not-a-knot cubic spline."""
    W, path, _ = joint_path_knots(waypoints)
    return W, path


def joint_path_knots(waypoints: np.ndarray) -> tuple[np.ndarray, JointSpline, list[float]]:
    """:func:`joint_path` and the path's parameter at each kept waypoint (0 … 1)."""
    W = np.array(waypoints, dtype=float)  # a copy: the path keeps its own waypoints
    if W.ndim == 2 and len(W) >= 2 and W.shape[1] < 8:  # the usual case, in Python floats
        rows = W.tolist()
        seg = [_chord(a, b) for a, b in pairwise(rows)]
        if all(v > 1e-9 for v in seg):  # no repeated waypoint
            return _through(W, rows, seg)
    seg_a = np.linalg.norm(np.diff(W, axis=0), axis=1)
    moved = seg_a > 1e-9
    if len(W) < 2 or not moved.all():  # repeated waypoints dropped (else W and seg stay as they are)
        W = W[np.concatenate([[True], moved])]
        if len(W) < 2:
            W = np.vstack([W, W])
            seg_a = np.array([1.0])
        else:
            seg_a = np.linalg.norm(np.diff(W, axis=0), axis=1)
    return _through(W, W.tolist(), seg_a.tolist())


def _chord(a: list[float], b: list[float]) -> float:
    """``np.linalg.norm(b − a)`` bit for bit for fewer than 8 values (numpy sums so few squares
    one after another from 0; from 8 on it sums pairwise, hence the caller's limit)."""
    total = 0.0
    for u, v in zip(a, b, strict=True):
        d = v - u
        total += d * d
    return math.sqrt(total)


def _through(W: np.ndarray, rows: list[list[float]], seg: list[float]) -> tuple[np.ndarray, JointSpline, list[float]]:
    """The path through the waypoints ``W`` (also as ``rows``) with chord lengths ``seg``: the
    knots are their running sums over the total (numpy's cumsum, then a division, in floats)."""
    if len(rows) == 2:  # a straight segment: linear in s
        return W, _Segment(W), [0.0, 1.0]
    knots, total = [0.0], 0.0
    for v in seg:
        total += v
        knots.append(total)
    knots = [k / total for k in knots]
    if len(rows) <= 4:
        return W, _Cubic(knots, rows), knots
    return W, CubicSpline(np.array(knots), W, axis=0, bc_type="not-a-knot"), knots


def path_values(path: JointSpline, s: list[float]) -> np.ndarray:
    """``path(s)`` (len(s), n) for a list of parameters: what the FK check of a straight line
    samples (:class:`_Cubic`'s by Horner's rule directly, the same operations as its ``path(s)``)."""
    if isinstance(path, _Cubic):
        a, b, c, d = path.c[:, 0]
        col = np.array(s)[:, None]
        return ((a * col + b) * col + c) * col + d
    return path(np.array(s))


def derivative_bounds(path: JointSpline) -> tuple[list[float], list[float]]:
    """Per joint, the exact maxima of |dq/ds| and |d²q/ds²| over s ∈ [0, 1] (Python floats): on
    each cubic piece the second derivative is linear (largest at an end) and the first quadratic
    (largest at an end or at its vertex)."""
    if isinstance(path, _Segment):
        return [abs(v) for v in path.delta.tolist()], [0.0] * len(path.delta)
    if isinstance(path, _Cubic):  # one piece on [0, 1], a few joints: scalar arithmetic is cheaper
        d1, d2 = [], []
        for a, b, c in zip(*path.c[:3, 0].tolist(), strict=True):  # a·s³ + b·s² + c·s + d
            m = max(abs(c), abs(3 * a + 2 * b + c))
            if a != 0.0 and 0.0 < -b / (3 * a) < 1.0:
                m = max(m, abs(c - b * b / (3 * a)))
            d1.append(m)
            d2.append(max(abs(2 * b), abs(6 * a + 2 * b)))
        return d1, d2
    c3, c2, c1 = path.c[0], path.c[1], path.c[2]  # (pieces, n): c3·t³ + c2·t² + c1·t + c0, t ∈ [0, h]
    h = np.diff(path.x)[:, None]
    d2 = np.maximum(np.abs(2 * c2), np.abs(6 * c3 * h + 2 * c2)).max(axis=0)
    vertex = np.clip(np.divide(-c2, 3 * c3, out=np.zeros_like(c3), where=c3 != 0), 0.0, h)
    d1 = np.maximum.reduce([np.abs(c1), np.abs((3 * c3 * h + 2 * c2) * h + c1),
                            np.abs((3 * c3 * vertex + 2 * c2) * vertex + c1)]).max(axis=0)
    return d1.tolist(), d2.tolist()


class MinJerkPath(Trajectory):
    """q(t) = path(s(t / T)), rest to rest, through ``waypoints`` (k, n) with k ≥ 2 (the path of
    :func:`joint_path`). The duration is the least for which the joint velocities and
    accelerations stay within ``limits`` — a true bound, from the path's exact derivative maxima
    (:func:`derivative_bounds`) and the time law's peaks; ``path`` is the already-built
    ``joint_path(waypoints)`` when the caller has it (a straight line checked by FK)."""

    def __init__(self, waypoints: np.ndarray, limits: JointLimits, min_duration: float = 0.05,
                 path: tuple[np.ndarray, JointSpline] | None = None):
        self.waypoints, self.spline = joint_path(waypoints) if path is None else path
        d1, d2 = derivative_bounds(self.spline)
        self.path_bounds = (d1, d2)  # per joint, max |dq/ds| and |d²q/ds²| (rad): the EE's bound uses them too
        # in Python floats: each quotient, product and sum the one numpy's elementwise version makes
        t_vel = PEAK_SPEED * max(a / v for a, v in zip(d1, limits.velocity.tolist(), strict=True))
        t_acc = math.sqrt(max((b * PEAK_SPEED**2 + a * PEAK_ACCEL) / c
                              for a, b, c in zip(d1, d2, limits.acceleration.tolist(), strict=True)))
        self.duration = float(max(t_vel, t_acc, min_duration))

    def positions_velocities(self, t) -> tuple[np.ndarray, np.ndarray]:
        """``evaluate(t)``'s (q, qd) by the same arithmetic, without the accelerations, evaluated a
        joint at a time along the times (:meth:`CubicSpline.derivatives_by_column`): they come
        back as the transposes of those (n, N) arrays (the same values; not C-ordered)."""
        return self._positions_velocities(*self._law(t))

    def step_targets(self, dt: float, n: int) -> tuple[np.ndarray, np.ndarray]:
        """``positions_velocities(np.arange(1, n + 1) * dt)`` bit for bit: the times are ascending
        and positive, so the clip to [0, duration] only lowers a tail past the end, found from the
        end (one or two steps) instead of clipping every time."""
        t, i = np.arange(1, n + 1) * dt, n
        while i and t[i - 1] > self.duration:
            i -= 1
        t[i:] = self.duration
        return self._positions_velocities(*self._law_within(t))

    def _positions_velocities(self, tau: np.ndarray, tau2: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        sd = 30 * tau2  # 30τ²·(1 − τ)² / T, in place (x**2 is numpy's square)
        b = 1 - tau
        np.square(b, out=b)
        sd *= b
        sd /= self.duration
        if s.ndim == 1:
            if isinstance(self.spline, _Segment):  # q̇ = delta·ṡ: the same products, without the repeated delta
                return self.spline.derivatives_by_column(s, (0,))[0].T, (self.spline.delta[:, None] * sd).T
            q, d1 = self.spline.derivatives_by_column(s, (0, 1))
            d1 *= sd  # d1 is new: scaled in place, each element as d1 * sd[:, None] scales it
            return q.T, d1.T
        q, d1 = self.spline.derivatives(s, (0, 1))
        return q, d1 * sd[:, None]

    def positions(self, t) -> np.ndarray:
        """``evaluate(t)``'s q by the same arithmetic (C-ordered), without the derivatives."""
        _, _, s = self._law(t)
        if s.ndim == 1:
            return np.ascontiguousarray(self.spline.derivatives_by_column(s, (0,))[0].T)
        return self.spline.derivatives(s, (0,))[0]

    def _law(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(τ, τ², s) of the min-jerk law at times ``t`` (s; clipped to [0, duration]), as
        ``_eval`` computes them (τ**2 is τ squared, once)."""
        return self._law_within(np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration))

    def _law_within(self, tt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`_law` at times ``tt`` already within [0, duration] (no NaN aside): ``_eval``'s
        clip of τ = tt / duration to [0, 1] changes nothing there (a correctly rounded quotient of
        0 ≤ tt ≤ duration lies in [0, 1], with tt's sign of zero), so it is not made."""
        tau = tt / self.duration
        tau2 = tau**2
        u = 15 * tau  # 10 − 15τ + 6τ², then τ³ times it: _eval's operations, in place in new arrays
        np.subtract(10.0, u, out=u)
        u += 6 * tau2
        s = tau**3
        s *= u
        return tau, tau2, s

    def _eval(self, t):
        T = self.duration
        tau = np.clip(t / T, 0.0, 1.0)
        s = tau**3 * (10 - 15 * tau + 6 * tau**2)
        sd = 30 * tau**2 * (1 - tau) ** 2 / T
        sdd = 60 * tau * (1 - tau) * (1 - 2 * tau) / T**2
        q, d1, d2 = self.spline.derivatives(s, (0, 1, 2))
        return q, d1 * sd[:, None], d2 * sd[:, None] ** 2 + d1 * sdd[:, None]
