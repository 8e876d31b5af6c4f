"""Per-step joint bounds from position, velocity and acceleration limits (pure numpy).

All arrays are per arm joint: positions in rad (or m), velocities in rad/s, accelerations in rad/s².
"""

from __future__ import annotations

import numpy as np


def step_bounds(q: np.ndarray, dq_prev: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                v_max: np.ndarray, a_max: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Bounds ``lo ≤ Δq ≤ hi`` (rad) for one control step of ``dt`` seconds.

    Velocity: ``|Δq/dt| ≤ v_max``. Position: the joint can still brake to rest at its limit with
    ``a_max`` (``v ≤ sqrt(2·a_max·room)``) and never steps past it. Acceleration:
    ``|Δq/dt − dq_prev| ≤ a_max·dt``. When the acceleration band and the position/velocity band do
    not meet (the joint cannot brake in time), position and velocity win and the step is the
    band's nearest edge (the acceleration limit is exceeded for that step).
    """
    q, dq_prev = np.asarray(q, float), np.asarray(dq_prev, float)
    room_up = np.maximum(np.asarray(upper) - q, 0.0)
    room_dn = np.maximum(q - np.asarray(lower), 0.0)
    v_hi = np.minimum.reduce([np.asarray(v_max, float), np.sqrt(2.0 * a_max * room_up), room_up / dt])
    v_lo = -np.minimum.reduce([np.asarray(v_max, float), np.sqrt(2.0 * a_max * room_dn), room_dn / dt])
    a_lo = dq_prev - a_max * dt
    a_hi = dq_prev + a_max * dt
    lo = np.maximum(v_lo, a_lo)
    hi = np.minimum(v_hi, a_hi)
    above = a_lo > v_hi  # moving too fast towards +: brake as hard as the band allows
    below = a_hi < v_lo
    lo = np.where(above, v_hi, np.where(below, v_lo, lo))
    hi = np.where(above, v_hi, np.where(below, v_lo, hi))
    return lo * dt, hi * dt
