"""Geometric paths through joint-space waypoints, parameterised by ``s`` (chord length, rad).

The default path is a C² natural cubic spline through every waypoint with knots at the cumulative
joint-space distance (chord length), so it passes *exactly* through each waypoint and has
continuous curvature, which is what a time-optimal parameteriser needs to keep moving through
the waypoints. A cubic spline can overshoot between waypoints; if the overshoot would leave a
joint's limits, the path falls back to a shape-preserving PCHIP interpolant (C¹, never leaves the
range of its neighbouring waypoints, hence never leaves the limits). For ``stop_at_waypoints`` the
path is piecewise linear (see :mod:`robocfg.motion.trapezoid`).

Paths duck-type toppra's ``AbstractGeometricPath``: ``path(s, order)``, ``dof``, ``path_interval``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DUPLICATE_TOL = 1e-4  # rad (or m): consecutive waypoints closer than this (max-norm) are one waypoint
LIMIT_SAMPLES = 600  # per path, plus the knots: finds any overshoot beyond the limits


@dataclass(frozen=True)
class Dedup:
    """Waypoints with consecutive repeats removed; ``kept[i]`` is the input index of row ``i``."""

    waypoints: np.ndarray
    kept: list[int]
    dropped: list[int]


def drop_repeats(waypoints: np.ndarray, tol: float = DUPLICATE_TOL) -> Dedup:
    """Remove waypoints equal (within ``tol``, max-norm) to the previous kept one."""
    W = np.asarray(waypoints, dtype=float)
    kept, dropped = [0], []
    for i in range(1, len(W)):
        if np.max(np.abs(W[i] - W[kept[-1]])) <= tol:
            dropped.append(i)
        else:
            kept.append(i)
    return Dedup(W[kept], kept, dropped)


def chord_knots(waypoints: np.ndarray) -> np.ndarray:
    """Cumulative Euclidean joint-space distance at each waypoint (starts at 0)."""
    W = np.asarray(waypoints, dtype=float)
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(W, axis=0), axis=1))])


class WaypointPath:
    """A piecewise-polynomial path q(s) through waypoints at ``knots`` (s in [0, knots[-1]])."""

    def __init__(self, knots: np.ndarray, waypoints: np.ndarray, kind: str, ppoly):
        self.knots = np.asarray(knots, dtype=float)
        self._waypoints = np.asarray(waypoints, dtype=float)
        self.kind = kind
        self._p = [ppoly, ppoly.derivative(1), ppoly.derivative(2)]

    def __call__(self, s, order: int = 0) -> np.ndarray:
        return self._p[order](s)

    @property
    def dof(self) -> int:
        return self._waypoints.shape[1]

    @property
    def path_interval(self) -> np.ndarray:
        return np.array([self.knots[0], self.knots[-1]])

    @property
    def waypoints(self):
        return self.knots, self._waypoints

    def range(self, samples: int = LIMIT_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
        """Per-joint (min, max) of q over the path, from dense sampling plus the knots."""
        s = np.union1d(np.linspace(self.knots[0], self.knots[-1], samples), self.knots)
        q = self(s)
        return q.min(axis=0), q.max(axis=0)


def spline_path(waypoints: np.ndarray) -> WaypointPath:
    """Natural cubic spline (C²) through ``waypoints`` (k, n), k ≥ 2, with chord-length knots."""
    from scipy.interpolate import CubicSpline

    W = np.asarray(waypoints, dtype=float)
    s = chord_knots(W)
    return WaypointPath(s, W, "spline", CubicSpline(s, W, axis=0, bc_type="natural"))


def pchip_path(waypoints: np.ndarray) -> WaypointPath:
    """Shape-preserving cubic (C¹) through ``waypoints``: no joint leaves its neighbours' range."""
    from scipy.interpolate import PchipInterpolator

    W = np.asarray(waypoints, dtype=float)
    s = chord_knots(W)
    return WaypointPath(s, W, "pchip", PchipInterpolator(s, W, axis=0))


def smooth_path(waypoints: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                bounded: np.ndarray | None = None) -> WaypointPath:
    """The spline through ``waypoints``, or the PCHIP path if the spline leaves [lower, upper]."""
    path = spline_path(waypoints)
    lo, hi = path.range()
    mask = np.ones(path.dof, dtype=bool) if bounded is None else np.asarray(bounded, dtype=bool)
    if np.any((lo < lower - 1e-9)[mask]) or np.any((hi > upper + 1e-9)[mask]):
        return pchip_path(waypoints)
    return path
