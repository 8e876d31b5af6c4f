"""The roll of an axis-symmetric tool about its own axis: not tracked, not counted.

A suction cup (or any tool symmetric about the axis it points along, the robot's ``ee_axis``)
does the same job at every roll about that axis, so a target orientation written for another
robot's hand fixes one more angle than the tool has. These helpers take that angle out: the
target turned about its tool axis to the roll nearest the current pose, and the error that is
left, the angle between the two tool axes. Rotations are 3×3 world matrices; axis 0/1/2 = x/y/z
of the TCP frame; angles in rad.
"""

from __future__ import annotations

import math

import numpy as np


def _about(axis: int, angle: float) -> np.ndarray:
    """Rotation (3×3) by ``angle`` rad about frame axis ``axis``."""
    c, s = math.cos(angle), math.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R = np.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def nearest_roll(R_target: np.ndarray, R_current: np.ndarray, axis: int) -> np.ndarray:
    """``R_target`` turned about its own ``axis`` to the roll nearest ``R_current``: the twist of
    ``R_targetᵀ·R_current`` about ``axis`` (swing–twist split), so what is left between the result
    and ``R_current`` is a swing only, of ``axis_angle(R_target, R_current, axis)``."""
    E = np.asarray(R_target, float).T @ np.asarray(R_current, float)
    # quaternion (w, v) of E: only the axis component of v and w are needed for the twist
    w = math.sqrt(max(0.0, 1.0 + E[0, 0] + E[1, 1] + E[2, 2])) / 2
    i, j = (axis + 1) % 3, (axis + 2) % 3
    v_axis_4w = E[j, i] - E[i, j]  # 4·w·v_axis
    # v_axis from the diagonal when w ≈ 0 (a half turn): v_axis² = (1 + 2·E_aa − trace) / 4
    v_abs = math.sqrt(max(0.0, 1.0 + 2 * E[axis, axis] - (E[0, 0] + E[1, 1] + E[2, 2]))) / 2
    v_axis = math.copysign(v_abs, v_axis_4w) if abs(v_axis_4w) > 1e-12 else v_abs
    twist = 2.0 * math.atan2(v_axis, w)
    return np.asarray(R_target, float) @ _about(axis, twist)


def axis_angle(R_a: np.ndarray, R_b: np.ndarray, axis: int) -> float:
    """Angle (rad, 0..π) between the tool axes (column ``axis``) of two rotations."""
    c = float(np.dot(np.asarray(R_a)[:, axis], np.asarray(R_b)[:, axis]))
    return math.acos(max(-1.0, min(1.0, c)))
