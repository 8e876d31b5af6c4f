"""Whether a measured EE pose is within tolerance of a goal pose: the test every move's
convergence poll makes (:meth:`robocfg.motion.moves.ArmMover.converge`).

The reference errors are those of the 4x4 pose: ``dp = ‖p − p_goal‖`` (m, ``numpy.linalg.norm``)
and ``dr = rotation_angle(R, R_goal)`` (rad). A poll runs right after hundreds of physics steps,
when numpy's code and data are out of the caches and each small numpy call costs tens of µs, so
:meth:`PoseGoal.reached` decides from the pose as PyBullet gives it (position and quaternion
tuples) with Python floats. Its errors differ from numpy's only by rounding (BLAS may fuse the
multiply-adds of the dot products; ``arccos`` may be another implementation): at most about
1e-7 rad for ``dr`` (where it is near 0, ``arccos``' steep end) and 1e-15 relative for ``dp``.
Where a Python error lies within ``ROTATION_MARGIN`` / ``POSITION_MARGIN`` of its tolerance, the
reference errors decide, so the answer is always the reference's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from robocfg.geometry import pose_to_matrix, rotation_angle
from robocfg.geometry.rotation import quat_rows

POSITION_MARGIN = 1e-9  # m: a Python-float position error this close to its tolerance is decided by numpy's
ROTATION_MARGIN = 1e-6  # rad: the same for the orientation error


class PoseGoal:
    """The goal ``T`` (4x4, world) of a move with its tolerances (m, rad)."""

    def __init__(self, T: np.ndarray, position_tolerance: float, orientation_tolerance: float):
        self.T = np.asarray(T, dtype=float)
        self.position_tolerance, self.orientation_tolerance = float(position_tolerance), float(orientation_tolerance)
        self._p = self.T[:3, 3].tolist()
        self._R = self.T[:3, :3].tolist()

    def errors(self, T: np.ndarray) -> tuple[float, float]:
        """(position error m, orientation error rad) of the pose ``T`` (4x4): the reference."""
        dp = float(np.linalg.norm(T[:3, 3] - self.T[:3, 3]))
        return dp, rotation_angle(T[:3, :3], self.T[:3, :3])

    def errors_at(self, position: Sequence[float], quat_xyzw: Sequence[float]) -> tuple[float, float]:
        """:meth:`errors` of the pose given as position (m) and quaternion ``(x, y, z, w)``."""
        return self.errors(pose_to_matrix(position, quat_xyzw))

    def reached(self, position: Sequence[float], quat_xyzw: Sequence[float]) -> bool:
        """Whether both errors of the pose (position m, quaternion ``(x, y, z, w)``) are within
        their tolerances, as :meth:`errors` would decide it (module docstring)."""
        rows = quat_rows(quat_xyzw)
        if rows is None:  # not a unit-normable quaternion: the reference path (and its errors)
            dp, dr = self.errors_at(position, quat_xyzw)
            return dp <= self.position_tolerance and dr <= self.orientation_tolerance
        (gx, gy, gz), G = self._p, self._R
        x, y, z = position
        dx, dy, dz = x - gx, y - gy, z - gz
        dp = math.sqrt(dx * dx + dy * dy + dz * dz)
        trace = 0.0
        for r, g in zip(rows, G):  # noqa: B905 - 3 rows each
            trace += r[0] * g[0] + r[1] * g[1] + r[2] * g[2]
        dr = math.acos(min(max((trace - 1.0) / 2.0, -1.0), 1.0))
        ptol, rtol = self.position_tolerance, self.orientation_tolerance
        if abs(dp - ptol) <= POSITION_MARGIN or abs(dr - rtol) <= ROTATION_MARGIN:
            dp, dr = self.errors_at(position, quat_xyzw)
        return dp <= ptol and dr <= rtol
