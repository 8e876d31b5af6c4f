"""Rotation conversions (quaternion, roll-pitch-yaw, axis-angle, matrix) by scipy's ``Rotation``.

Quaternions are ``(x, y, z, w)``; roll-pitch-yaw angles are extrinsic X-Y-Z (``R = Rz·Ry·Rx``),
the convention of URDF ``rpy`` and of PyBullet's ``getQuaternionFromEuler``. Matrices are 3x3
numpy arrays (float64).

scipy is imported inside the functions, and the conversions that URDF parsing, URDF forward
kinematics and task poses need (:func:`rpy_matrix`, :func:`axis_angle_matrix`,
:func:`euler_deg_to_quat_xyzw`, one :func:`quat_to_matrix`) are closed forms: ``robocfg
validate`` parses every robot's URDF and every process reads task poses, and importing
``scipy.spatial`` costs about 0.3 s of CPU, more than half of what validating the built-in
robots takes. The closed forms are tested against scipy's ``Rotation``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np


def quat_to_matrix(q: Sequence[float] | np.ndarray) -> np.ndarray:
    """3x3 rotation of a quaternion ``(x, y, z, w)`` (normalised first); (N, 3, 3) for (N, 4).

    One quaternion is converted in closed form with scipy's own arithmetic (the same bits as
    ``Rotation.from_quat(q).as_matrix()``, tested; ≈ 5× cheaper: it runs for every link pose
    read while simulating)."""
    rows = quat_rows(q)
    if rows is not None:
        return np.array(rows)
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(np.asarray(q, dtype=float)).as_matrix()


def quat_rows(q: Sequence[float] | np.ndarray) -> list[list[float]] | None:
    """The rows of :func:`quat_to_matrix` of one quaternion ``(x, y, z, w)`` as Python floats (the
    same bits), or None where its closed form does not apply (not one quaternion, zero or not
    finite): for code that reads a rotation's entries one by one."""
    if type(q) is tuple and len(q) == 4:  # as PyBullet gives it: no array round trip
        x, y, z, w = (float(v) for v in q)
    else:
        a = np.asarray(q, dtype=float)
        if a.shape != (4,):
            return None
        x, y, z, w = a.tolist()
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if not (n > 0.0 and math.isfinite(n)):
        return None
    x, y, z, w = x / n, y / n, z / n, w / n
    x2, y2, z2, w2 = x * x, y * y, z * z, w * w
    xy, zw, xz, yw, yz, xw = x * y, z * w, x * z, y * w, y * z, x * w
    return [[x2 - y2 - z2 + w2, 2 * (xy - zw), 2 * (xz + yw)],
            [2 * (xy + zw), -x2 + y2 - z2 + w2, 2 * (yz - xw)],
            [2 * (xz - yw), 2 * (yz + xw), -x2 - y2 + z2 + w2]]


def matrix_to_quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternion ``(x, y, z, w)`` of a 3x3 rotation matrix, with ``w >= 0``."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(np.asarray(R, dtype=float)).as_quat(canonical=True)


def euler_deg_to_quat_xyzw(rpy_deg: Sequence[float]) -> tuple[float, float, float, float]:
    """Roll, pitch, yaw in degrees (``R = Rz·Ry·Rx``) to a unit quaternion ``(x, y, z, w)``.

    In closed form with scipy's own arithmetic (elementary quaternions composed z·(y·x) as
    ``Rotation.from_euler("xyz", ..., degrees=True).as_quat()`` does; the same bits, tested): every
    task body's pose goes through here, and importing ``scipy.spatial`` costs a fresh process
    0.2–1 s."""
    r, p, y = (float(v) * (math.pi / 180.0) for v in rpy_deg)
    qx = (math.sin(r / 2.0), 0.0, 0.0, math.cos(r / 2.0))
    qy = (0.0, math.sin(p / 2.0), 0.0, math.cos(p / 2.0))
    qz = (0.0, 0.0, math.sin(y / 2.0), math.cos(y / 2.0))
    return _compose_quat(qz, _compose_quat(qy, qx))


def _compose_quat(p: tuple[float, float, float, float],
                  q: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    """The quaternion product p·q, term for term in scipy's order (``_compose_quat_single``)."""
    c0 = p[1] * q[2] - p[2] * q[1]
    c1 = p[2] * q[0] - p[0] * q[2]
    c2 = p[0] * q[1] - p[1] * q[0]
    return (p[3] * q[0] + q[3] * p[0] + c0, p[3] * q[1] + q[3] * p[1] + c1, p[3] * q[2] + q[3] * p[2] + c2,
            p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2])


def rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """3x3 rotation of URDF roll, pitch, yaw in radians (``R = Rz(y)·Ry(p)·Rx(r)``)."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def axis_angle_matrix(axis: Sequence[float] | np.ndarray, angle: float) -> np.ndarray:
    """3x3 rotation by ``angle`` (rad) about ``axis`` (any non-zero length; normalised here),
    by Rodrigues' formula."""
    a = np.asarray(axis, dtype=float)
    x, y, z = a / np.linalg.norm(a)
    K = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def rotation_angle(Ra: np.ndarray, Rb: np.ndarray) -> float:
    """Angle (rad, in [0, π]) of the rotation that takes ``Ra`` to ``Rb``."""
    c = (np.trace(np.asarray(Ra).T @ np.asarray(Rb)) - 1.0) / 2.0
    return float(np.arccos(np.clip(c, -1.0, 1.0)))
