"""Target motions for follow-target: position (m, world) and pose (4×4) as functions of time (s).

See :class:`robocfg.config.commands.Motion` for the motion types. Velocities are central
differences of the pose (``h`` = 1 ms), returned as (vx, vy, vz, wx, wy, wz) in m/s and rad/s.
"""

from __future__ import annotations

import math

import numpy as np

from robocfg.config.commands import MOTION_TYPES, Motion
from robocfg.geometry import axis_angle_matrix

PLANE_AXES = {"xy": (0, 1), "yz": (1, 2), "xz": (0, 2)}
DEFAULT_SEGMENT_TIME = 2.0  # s between waypoints when no times are given


class TargetMotion:
    """A target that moves as ``motion`` says, with orientation ``R0`` (fixed) or swinging about the
    motion plane's normal by ``follow_angle·sin(2π·t/period)`` rad (``following``)."""

    def __init__(self, motion: Motion, R0: np.ndarray | None = None, orientation: str = "fixed",
                 follow_angle: float = 0.0):
        if motion.type not in MOTION_TYPES:  # the config model already rejects these
            raise ValueError(f"unknown motion type {motion.type!r}; valid: {', '.join(MOTION_TYPES)}")
        self.m = motion
        self.R0 = np.eye(3) if R0 is None else np.asarray(R0, float)
        self.orientation, self.follow_angle = orientation, follow_angle
        self.center = np.asarray(motion.center, float)
        a, b = PLANE_AXES[motion.plane]
        self.u, self.v = np.eye(3)[a], np.eye(3)[b]
        self.normal = np.cross(self.u, self.v)
        if motion.type == "waypoints":
            pts = np.asarray(motion.waypoints, float)
            times = (np.asarray(motion.waypoint_times, float) if motion.waypoint_times
                     else DEFAULT_SEGMENT_TIME * np.arange(len(pts)))
            self.points, self.times = pts, times

    @property
    def end_time(self) -> float:
        """When the motion comes to rest for good (s); inf for periodic motions."""
        if self.m.type == "static":
            return 0.0
        if self.m.type == "waypoints" and not self.m.loop:
            return float(self.times[-1])
        return math.inf

    def position(self, t: float) -> np.ndarray:
        m = self.m
        if m.type == "static":
            return self.center.copy()
        if m.type == "waypoints":
            return self._waypoints(t)
        phase = 2.0 * math.pi * t / m.period
        if m.type == "circle":
            return self.center + m.radius * (math.cos(phase) * self.u + math.sin(phase) * self.v)
        # figure8 (lemniscate of Gerono): through the centre at t = 0
        return self.center + m.radius * (math.sin(phase) * self.u + math.sin(phase) * math.cos(phase) * self.v)

    def _waypoints(self, t: float) -> np.ndarray:
        pts, times = self.points, self.times
        if len(pts) == 1 or t <= times[0]:
            return pts[0].copy()
        if self.m.loop:
            span = times[-1] + (times[-1] - times[-2] if len(times) > 1 else DEFAULT_SEGMENT_TIME)
            t = t % span
            if t > times[-1]:  # back to the first waypoint
                s = (t - times[-1]) / (span - times[-1])
                return pts[-1] + (pts[0] - pts[-1]) * _smooth(s)
        if t >= times[-1]:
            return pts[-1].copy()
        k = int(np.searchsorted(times, t, side="right")) - 1
        s = (t - times[k]) / (times[k + 1] - times[k])
        return pts[k] + (pts[k + 1] - pts[k]) * _smooth(s)

    def rotation(self, t: float) -> np.ndarray:
        if self.orientation != "following" or self.follow_angle == 0.0:
            return self.R0.copy()
        angle = self.follow_angle * math.sin(2.0 * math.pi * t / self.m.period)
        return axis_angle_matrix(self.normal, angle) @ self.R0

    def pose(self, t: float) -> np.ndarray:
        T = np.eye(4)
        T[:3, :3] = self.rotation(t)
        T[:3, 3] = self.position(t)
        return T

    def velocity(self, t: float, h: float = 1e-3) -> np.ndarray:
        """(v, ω) of the target at ``t``: m/s and rad/s, world frame."""
        v = (self.position(t + h) - self.position(t - h)) / (2 * h)
        Ra, Rb = self.rotation(t - h), self.rotation(t + h)
        W = (Rb - Ra) @ self.rotation(t).T / (2 * h)  # skew(ω)
        return np.concatenate([v, [W[2, 1], W[0, 2], W[1, 0]]])


def _smooth(s: float) -> float:
    """Minimum-jerk blend 0 → 1 (zero velocity and acceleration at both ends)."""
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
