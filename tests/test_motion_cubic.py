"""robocfg.motion.cubic.CubicSpline gives scipy.interpolate.CubicSpline's values bit for bit (so
moves and golden reports do not change with it), and refuses what it does not implement."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline as ScipySpline

from robocfg.motion.cubic import CubicSpline


@pytest.mark.parametrize("bc", ["not-a-knot", "natural"])
def test_values_and_derivatives_are_scipys_bits(bc):
    rng = np.random.default_rng(11)
    for trial in range(300):
        k = int(rng.integers(4 if bc == "not-a-knot" else 2, 30))
        x = np.concatenate([[0.0], np.cumsum(rng.uniform(1e-4, 1.0, k - 1))])
        if trial % 2:
            x /= x[-1]  # the chord-length knots MinJerkPath uses
        y = rng.normal(size=(k, int(rng.integers(1, 8))))
        theirs, ours = ScipySpline(x, y, axis=0, bc_type=bc), CubicSpline(x, y, axis=0, bc_type=bc)
        xs = np.concatenate([np.linspace(x[0], x[-1], 64), x, rng.uniform(x[0] - 0.2, x[-1] + 0.2, 20), [np.nan]])
        for nu in range(4):
            a, b = theirs(xs, nu), ours(xs, nu)
            assert a.shape == b.shape and a.tobytes() == b.tobytes(), (trial, nu)
        nus = [(0, 1), (1, 2), (0, 1, 2), (2, 0, 3, 1)][trial % 4]  # several at once, sharing the lookup
        for nu, b in zip(nus, ours.derivatives(xs, nus), strict=True):
            assert b.tobytes() == theirs(xs, nu).tobytes(), (trial, nus, nu)
        for nu, b in zip(nus, ours.derivatives_by_column(xs, nus), strict=True):  # one row per column of y
            assert b.shape == (y.shape[1], len(xs)) and b.T.tobytes() == theirs(xs, nu).tobytes(), (trial, nus, nu)
        s = np.float64(x[-1] * 0.37)
        assert ours(s).shape == theirs(s).shape and ours(s).tobytes() == theirs(s).tobytes()


def test_interpolates_the_waypoints():
    x = np.array([0.0, 0.2, 0.5, 0.9, 1.0])
    y = np.array([[0.0, 1.0], [0.3, 0.8], [0.1, 0.2], [0.7, -0.4], [1.0, 0.0]])
    assert np.allclose(CubicSpline(x, y)(x), y, atol=1e-12)
    assert np.allclose(CubicSpline(x, y, bc_type="natural")(x[[0, -1]], 2), 0.0, atol=1e-9)


def test_refuses_what_it_does_not_implement():
    x, y = np.array([0.0, 0.5, 1.0]), np.zeros((3, 2))
    with pytest.raises(ValueError):
        CubicSpline(x, y)  # not-a-knot with 3 points: scipy's parabola case, not here
    with pytest.raises(ValueError):
        CubicSpline(x[::-1], y, bc_type="natural")
    with pytest.raises(ValueError):
        CubicSpline(x, y, bc_type="clamped")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        CubicSpline(x, y, bc_type="natural").derivatives_by_column(np.zeros((2, 2)), (0,))
