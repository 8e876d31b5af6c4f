"""How much to slow a timed move so that the EE's acceleration stays within what a grip carries.

The measure (as before): the EE position (``ee`` frame, world, m) by FK at ``ACCEL_SAMPLES``
instants, its peak second difference over the squared interval (m/s²); time scaled by c scales
accelerations by 1/c², so the factor is ``sqrt(peak / limit)`` when that is more than 1.

The measure costs 41 FK evaluations and a sampled trajectory; most moves need no slowing at all
(a pick-place carry peaks at 1–8 % of the grip's limit). For a :class:`MinJerkPath` on an arm of
revolute joints a bound answers first, at the cost of a few dozen multiplications:
``p̈ = Σ_j J_j q̈_j + Σ_ij H_ij q̇_i q̇_j`` with ``|J_j| ≤ R_j`` and ``|H_ij| ≤ min(R_i, R_j)``
(:mod:`robocfg.kinematics.lever_arms`), ``|q̇_j| ≤ d1_j ṡ_max`` and
``|q̈_j| ≤ d2_j ṡ_max² + d1_j |s̈|_max`` (the path's exact derivative maxima d1, d2 over s, and the
min-jerk law's peaks ṡ_max = 1.875/T, |s̈|_max = (10/√3)/T²). A second difference over an interval
h is a weighted mean of p̈ (``p(t+h) − 2p(t) + p(t−h) = ∫ (h − |u|) p̈(t+u) du``), so it never
exceeds that bound: when the bound is within the limit, the measure would give a factor of
exactly 1, and is not taken. Otherwise it is, and its factor is returned unchanged.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from robocfg.motion.minjerk_path import PEAK_SPEED, MinJerkPath

if TYPE_CHECKING:
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.trajectory import Trajectory

ACCEL_SAMPLES = 41  # instants at which a move's EE acceleration is measured against the limit
MIN_ACCELERATION = 0.5  # m/s²: the lowest EE acceleration limit honoured (a tighter one would crawl)
LAW_PEAK_ACCEL = 10.0 / math.sqrt(3.0)  # max |d²s/dτ²| of the min-jerk law (at τ = (3 ± √3)/6)
BOUND_SLACK = 1e-6  # m/s² (and 1e-9 relative) for rounding in the measure and in the bound


def stretch_factor(model: KinematicModel, traj: Trajectory, a_max: float) -> float:
    """Factor (≥ 1) by which to slow ``traj`` (its time scaled) so that the EE's peak
    acceleration, measured as the module docstring says, stays within ``a_max`` (m/s², at least
    ``MIN_ACCELERATION``): 1.0 without measuring when the bound proves it."""
    limit = max(a_max, MIN_ACCELERATION)
    if isinstance(traj, MinJerkPath) and traj.duration > 0:
        levers = model.lever_arms("ee")
        if levers is not None:
            d1, d2 = traj.path_bounds
            if acceleration_bound(levers, d1, d2, traj.duration) * (1 + 1e-9) + BOUND_SLACK <= limit:
                return 1.0
    t = np.linspace(0.0, traj.duration, ACCEL_SAMPLES)
    P = model.fk_positions(traj.positions(t), "ee")
    peak = float(np.linalg.norm(np.diff(P, 2, axis=0), axis=1).max()) / (t[1] - t[0]) ** 2
    return max(1.0, math.sqrt(peak / limit))


def acceleration_bound(levers: tuple[float, ...], d1: list[float], d2: list[float], duration: float) -> float:
    """Upper bound (m/s²) on the EE's acceleration along a min-jerk move of ``duration`` s whose
    path has per-joint derivative maxima ``d1`` (|dq/ds|) and ``d2`` (|d²q/ds²|), for an arm with
    lever arms ``levers`` (m): the module docstring's sum, its double sum
    ``Σ_ij min(R_i, R_j) v_i v_j`` taken in order of decreasing lever as ``Σ_j R_j v_j (2 V_j − v_j)``
    (``V_j`` the sum of the v up to j)."""
    sv = PEAK_SPEED / duration
    sa = LAW_PEAK_ACCEL / (duration * duration)
    total = cumulative = 0.0
    for R, a, b in sorted(zip(levers, d1, d2, strict=True), reverse=True):
        v = a * sv  # |q̇_j| bound
        cumulative += v
        total += R * (b * sv * sv + a * sa + v * (2.0 * cumulative - v))
    return total
