"""joint_travel: numpy's ``np.max(np.abs(b − a))`` in Python floats, NaN included."""

from __future__ import annotations

import math

import numpy as np

from robocfg.motion.joint_travel import joint_travel


def test_joint_travel_is_numpys_largest_change():
    rng = np.random.default_rng(1)
    for n in (1, 6, 7):
        for _ in range(200):
            a, b = rng.normal(size=n), rng.normal(size=n) * rng.choice([1e-8, 1.0, 100.0])
            assert joint_travel(a, b) == float(np.max(np.abs(b - a)))
    a = np.zeros(7)
    for i in (0, 3, 6):  # a NaN anywhere gives NaN, as numpy's reduction does (Python's max would not)
        b = np.ones(7)
        b[i] = np.nan
        assert math.isnan(joint_travel(a, b)) and math.isnan(float(np.max(np.abs(b - a))))
