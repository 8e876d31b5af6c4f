"""MinJerkPath: what a played move samples is evaluate()'s positions and velocities, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.motion.limits import JointLimits
from robocfg.motion.minjerk_path import MinJerkPath


@pytest.mark.parametrize("k", [2, 3, 4, 7])
def test_positions_velocities_are_evaluates_bits(k):
    rng = np.random.default_rng(k)
    W = np.cumsum(rng.normal(0.0, 0.2, (k, 7)), axis=0)
    limits = JointLimits(names=tuple("abcdefg"), lower=np.full(7, -4.0), upper=np.full(7, 4.0),
                         velocity=np.full(7, 2.0), acceleration=np.full(7, 6.0))
    path = MinJerkPath(W, limits)
    t = np.arange(1, int(path.duration * 240) + 5) / 240  # past the end too (clipped)
    q, qd = path.positions_velocities(t)
    q_ref, qd_ref, _ = path.evaluate(t)
    assert q.shape == q_ref.shape and qd.shape == qd_ref.shape
    assert q.tobytes() == q_ref.tobytes() and qd.tobytes() == qd_ref.tobytes()
    t_few = np.linspace(-0.1, path.duration + 0.1, 41)
    assert path.positions(t_few).tobytes() == path.evaluate(t_few)[0].tobytes()  # what a move's FK check samples
    assert path.positions(t_few).flags.c_contiguous
    assert np.allclose(q[-1], W[-1], atol=1e-12) and np.abs(qd).max() > 0.1  # it moved, and ends at the goal


@pytest.mark.parametrize("k", [2, 3, 4, 7])
@pytest.mark.parametrize("dt", [1 / 240, 0.002, 0.01])
def test_step_targets_are_positions_velocities_bits(k, dt):
    """What ArmMover.play sends (the step times k·dt, the last ones past the end) is
    positions_velocities' answer bit for bit, also with a stretched duration (a held load), and
    evaluate's (q, qd)."""
    import math

    rng = np.random.default_rng(10 + k)
    limits = JointLimits(names=tuple("abcdefg"), lower=np.full(7, -4.0), upper=np.full(7, 4.0),
                         velocity=np.full(7, 2.0), acceleration=np.full(7, 6.0))
    for trial in range(10):
        path = MinJerkPath(np.cumsum(rng.normal(0.0, 0.2, (k, 7)), axis=0), limits)
        if trial % 2:
            path.duration *= 1.0 + rng.uniform(0.0, 0.7)
        for n in (math.ceil(path.duration / dt - 1e-9), math.ceil(path.duration / dt) + 3, 1, 0):
            t = np.arange(1, n + 1) * dt  # the second n: three steps past the end
            got, ref = path.step_targets(dt, n), path.positions_velocities(t)
            for a, b in zip(got, ref, strict=True):
                assert a.shape == b.shape and a.tobytes() == b.tobytes() and a.strides == b.strides, (k, trial, n)
            assert all(np.ascontiguousarray(a).tobytes() == b.tobytes() for a, b in zip(got, path.evaluate(t), strict=False))


@pytest.mark.parametrize("k", [2, 3, 4, 5, 9])
def test_duration_keeps_velocities_and_accelerations_within_the_limits(k):
    """The duration is a true bound: sampled densely (2000 instants), no joint's speed or
    acceleration exceeds its limit, and the bound is not loose (one of them comes within 10 %)."""
    rng = np.random.default_rng(100 + k)
    for trial in range(20):
        W = np.cumsum(rng.normal(0.0, 0.3, (k, 6)), axis=0)
        limits = JointLimits(names=tuple("abcdef"), lower=np.full(6, -9.0), upper=np.full(6, 9.0),
                             velocity=rng.uniform(0.5, 3.0, 6), acceleration=rng.uniform(1.0, 10.0, 6))
        path = MinJerkPath(W, limits)
        _, qd, qdd = path.evaluate(np.linspace(0.0, path.duration, 2000))
        v, a = np.abs(qd).max(axis=0) / limits.velocity, np.abs(qdd).max(axis=0) / limits.acceleration
        assert v.max() <= 1 + 1e-9 and a.max() <= 1 + 1e-9, (k, trial)
        if k == 2:
            assert max(v.max(), a.max()) > 0.999, trial


@pytest.mark.parametrize("k", [3, 4])
def test_few_waypoints_give_scipys_not_a_knot_spline_and_exact_derivative_bounds(k):
    """Three or four waypoints: the one polynomial through them is scipy's not-a-knot spline (to
    rounding), and the derivative maxima the duration uses are the true ones (20001 samples)."""
    from scipy.interpolate import CubicSpline as ScipySpline

    from robocfg.motion.minjerk_path import derivative_bounds, joint_path

    rng = np.random.default_rng(k)
    for _ in range(100):
        W = np.cumsum(rng.normal(size=(k, 6)), axis=0)
        _, path = joint_path(W)
        x = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(W, axis=0), axis=1))])
        ref = ScipySpline(x / x[-1], W, bc_type="not-a-knot")
        s = np.linspace(0.0, 1.0, 101)
        for nu in range(4):
            assert np.allclose(path(s, nu), ref(s, nu), rtol=0, atol=1e-8 * (1 + np.abs(ref(s, nu)).max()))
        d1, d2 = derivative_bounds(path)
        dense = np.linspace(0.0, 1.0, 20001)
        assert np.all(d1 >= np.abs(ref(dense, 1)).max(axis=0) - 1e-9)
        assert np.all(d1 <= np.abs(ref(dense, 1)).max(axis=0) * (1 + 1e-6) + 1e-9)
        assert np.allclose(d2, np.abs(ref(dense, 2)).max(axis=0))


def _numpy_joint_path_knots(waypoints):
    """The path's knots and polynomial coefficients as the numpy version computed them (seventh
    session): the reference for the Python-float version's bits."""
    W = np.array(waypoints, dtype=float)
    seg = np.linalg.norm(np.diff(W, axis=0), axis=1)
    moved = seg > 1e-9
    if len(W) < 2 or not moved.all():
        W = W[np.concatenate([[True], moved])]
        seg = np.linalg.norm(np.diff(W, axis=0), axis=1) if len(W) >= 2 else np.array([1.0])
        if len(W) < 2:
            W = np.vstack([W, W])
    if len(W) == 2:
        return W, np.array([0.0, 1.0]), None
    x = np.concatenate([[0.0], np.cumsum(seg)])
    x /= x[-1]
    if len(W) > 4:
        return W, x, None
    f01 = (W[1] - W[0]) / (x[1] - x[0])
    f12 = (W[2] - W[1]) / (x[2] - x[1])
    f012 = (f12 - f01) / (x[2] - x[0])
    if len(W) == 4:
        f23 = (W[3] - W[2]) / (x[3] - x[2])
        f0123 = ((f23 - f12) / (x[3] - x[1]) - f012) / (x[3] - x[0])
    else:
        f0123 = np.zeros_like(f012)
    x1, x2 = float(x[1]), float(x[2]) if len(W) == 4 else 0.0
    return W, x, np.stack((f0123, f012 - f0123 * (x1 + x2), f01 - f012 * x1 + f0123 * x1 * x2, W[0]))[:, None, :]


@pytest.mark.parametrize("n", [6, 7, 8, 9])
def test_joint_path_knots_in_floats_are_the_numpy_versions_bits(n):
    """Knots and coefficients (what a move plays) are the bits the numpy version made, for every
    waypoint count, scale and joint count (from 8 joints numpy's pairwise sums are used as they are)."""
    from robocfg.motion.minjerk_path import _Cubic, _Segment, joint_path_knots

    rng = np.random.default_rng(n)
    for k in (2, 3, 4, 5, 7):
        for _ in range(200):
            W = np.cumsum(rng.normal(0.0, 0.3, (k, n)) * rng.choice([1e-4, 1.0, 30.0], (k, n)), axis=0)
            if rng.random() < 0.1:
                W[-1] = W[-2]  # a repeated waypoint: dropped
            W_ref, x_ref, c_ref = _numpy_joint_path_knots(W)
            W_new, path, knots = joint_path_knots(W)
            assert W_new.tobytes() == W_ref.tobytes()
            assert np.array(knots).tobytes() == x_ref.tobytes()
            if c_ref is not None:
                assert isinstance(path, _Cubic) and path.c.tobytes() == c_ref.tobytes()
            elif len(W_ref) == 2:
                assert isinstance(path, _Segment)
            else:
                assert path.x.tobytes() == x_ref.tobytes()
