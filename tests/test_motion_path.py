"""robocfg.motion.path: repeated waypoints, the spline through waypoints, the PCHIP fallback."""

from __future__ import annotations

import numpy as np

from robocfg.motion.path import chord_knots, drop_repeats, pchip_path, smooth_path, spline_path


def test_drop_repeats_keeps_first_and_reports_indices():
    W = np.array([[0, 0], [0, 0], [1, 0], [1, 5e-5], [1, 1], [0, 0]], dtype=float)
    d = drop_repeats(W)
    assert d.kept == [0, 2, 4, 5]
    assert d.dropped == [1, 3]
    assert np.array_equal(d.waypoints, W[[0, 2, 4, 5]])


def test_spline_passes_through_every_waypoint_with_continuous_curvature():
    rng = np.random.default_rng(1)
    W = rng.uniform(-1, 1, size=(6, 3))
    p = spline_path(W)
    assert np.allclose(p(p.knots), W, atol=1e-12)
    assert np.allclose(p.knots, chord_knots(W))
    eps = 1e-7
    for s in p.knots[1:-1]:  # C²: first and second derivatives agree on both sides of a knot
        assert np.allclose(p(s - eps, 1), p(s + eps, 1), atol=1e-5)
        assert np.allclose(p(s - eps, 2), p(s + eps, 2), atol=1e-4)
    assert p.dof == 3 and p.path_interval[0] == 0.0


def test_pchip_fallback_when_the_spline_overshoots_a_limit():
    # joint 0 rises to its upper limit and stays: a cubic spline overshoots above 1.0
    W = np.array([[0.0, 0.0], [1.0, 0.2], [1.0, 0.6], [0.0, 1.0]])
    lower, upper = np.array([-1.0, -1.0]), np.array([1.0, 1.0])
    assert spline_path(W).range()[1][0] > 1.0 + 1e-6
    p = smooth_path(W, lower, upper)
    assert p.kind == "pchip"
    lo, hi = p.range()
    assert np.all(hi <= upper + 1e-12) and np.all(lo >= lower - 1e-12)
    assert np.allclose(p(p.knots), W)
    # within limits: the spline is kept
    assert smooth_path(W * 0.5, lower, upper).kind == "spline"
    assert pchip_path(W).kind == "pchip"
