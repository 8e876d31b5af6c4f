"""Rigid poses: ``(position, quat_xyzw)`` ↔ 4x4 homogeneous transforms. Positions in metres."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from robocfg.geometry.rotation import matrix_to_quat, quat_rows, quat_to_matrix


class HasPose(Protocol):
    """Anything with a ``position`` (m) and an orientation as a quaternion, e.g. a config ``Pose``."""

    @property
    def position(self) -> Sequence[float]: ...

    def quaternion_xyzw(self) -> tuple[float, float, float, float]: ...


def pose_to_matrix(position: Sequence[float] | np.ndarray, quat_xyzw: Sequence[float] | np.ndarray) -> np.ndarray:
    """4x4 transform from a position (m) and a quaternion ``(x, y, z, w)``. Built in one array
    from :func:`~robocfg.geometry.rotation.quat_rows` where it applies (every link pose read while
    simulating comes here); the same values as filling an identity."""
    rows = quat_rows(quat_xyzw)
    if rows is not None and (type(position) in (tuple, list) or getattr(position, "ndim", 0) == 1) and len(position) == 3:
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rows
        x, y, z = position
        return np.array([[r00, r01, r02, x], [r10, r11, r12, y], [r20, r21, r22, z], [0.0, 0.0, 0.0, 1.0]],
                        dtype=float)
    T = np.eye(4)
    T[:3, :3] = quat_to_matrix(quat_xyzw)
    T[:3, 3] = position
    return T


def pose_matrix(pose: HasPose) -> np.ndarray:
    """4x4 world transform of a pose-like object (a config ``Pose`` and its subclasses)."""
    return pose_to_matrix(pose.position, pose.quaternion_xyzw())


def matrix_to_pose(T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(position (3,), quat_xyzw (4,))`` of a 4x4 transform."""
    return np.asarray(T[:3, 3], dtype=float).copy(), matrix_to_quat(T[:3, :3])
