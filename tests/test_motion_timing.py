"""Timing: toppra along the spline, stop-at-waypoint trapezoids, ruckig with jerk, plan_trajectory."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robocfg.motion.limits import make_limits
from robocfg.motion.path import spline_path
from robocfg.motion.plan import plan_trajectory
from robocfg.motion.timing import time_optimal
from robocfg.motion.trajectory import check_limits
from robocfg.motion.trapezoid import TrapezoidSegment, stop_at_waypoints

HOME = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
REACH = np.array([0.5, 0.1, 0.2, -1.7, 0.1, 1.9, 0.9])
_U = np.linspace(0.0, 1.0, 6)[:, None]
SWEEP = (HOME + _U * np.array([1.6, 0.4, 0.3, 0.6, 0.4, 0.3, -0.5])  # six waypoints on a curved route
         + np.sin(np.pi * _U) * np.array([0.0, 0.5, -0.4, 0.4, 0.0, 0.3, 0.0]))
LOWER = np.array([-2.9, -1.76, -2.9, -3.07, -2.9, -0.02, -2.9])
UPPER = np.array([2.9, 1.76, 2.9, -0.07, 2.9, 3.75, 2.9])
NAMES = [f"j{i + 1}" for i in range(7)]


def limits(v=1.0, a=5.0, jerk=None):
    vel = np.array([2.175] * 4 + [2.61] * 3) * v
    return make_limits(NAMES, LOWER, UPPER, vel, np.full(7, a), jerk)


def test_toppra_respects_limits_passes_waypoints_and_is_near_optimal():
    lim = limits()
    path = spline_path(SWEEP)
    tr = time_optimal(path, lim)
    check = check_limits(tr, lim, rate=1000.0)
    assert check.total == 0
    # time-optimal: some joint rides its velocity or acceleration limit
    assert max(check.peak_velocity_ratio, check.peak_acceleration_ratio) > 0.99
    ref = time_optimal(path, lim, gridpoints=1000, fit=False)
    assert tr.duration <= ref.duration * 1.02
    q, qd, _ = tr.evaluate([0.0, tr.duration])
    assert np.allclose(q, SWEEP[[0, -1]], atol=1e-9) and np.allclose(qd, 0.0, atol=1e-9)
    times = tr.f.time_at(path.knots) * tr.k
    assert np.allclose(tr.evaluate(times)[0], SWEEP, atol=1e-9)
    assert np.all(np.diff(times) > 0)


def test_through_waypoints_is_faster_than_stopping_on_a_sweep():
    lim = limits()
    smooth = plan_trajectory(SWEEP, lim).duration
    stop = plan_trajectory(SWEEP, lim, stop_at_waypoints=True).duration
    assert smooth < 0.8 * stop


def test_trapezoid_segment_matches_closed_form():
    lim = make_limits(["a", "b"], [-10, -10], [10, 10], [1.0, 2.0], [2.0, 2.0])
    seg = TrapezoidSegment(np.zeros(2), np.array([3.0, 1.0]), lim)  # joint a limits: V = 1/3, A = 2/3 per unit u
    assert seg.duration == pytest.approx(3.0 / 1.0 + 1.0 / 2.0)  # T = d/v + v/a for the limiting joint
    q, qd, _qdd = seg.evaluate(np.linspace(0, seg.duration, 500))
    assert np.allclose(q[-1], [3.0, 1.0]) and np.max(np.abs(qd[:, 0])) == pytest.approx(1.0)
    assert np.allclose(q[:, 1] / 1.0, q[:, 0] / 3.0)  # straight line, synchronised
    tri = TrapezoidSegment(np.zeros(2), np.array([0.1, 0.0]), lim)  # too short to reach v: triangle
    assert tri.duration == pytest.approx(2 * np.sqrt(0.1 / 2.0))


def test_stop_at_waypoints_is_at_rest_at_every_waypoint():
    lim = limits()
    W = np.array([HOME, REACH, HOME + 0.1])
    W[2, 3] = -2.256
    plan = plan_trajectory(W, lim, stop_at_waypoints=True)
    assert plan.method == "trapezoid"
    q, qd, _ = plan.trajectory.evaluate(plan.waypoint_times)
    assert np.allclose(q, W) and np.allclose(qd, 0.0)
    assert check_limits(plan.trajectory, lim).total == 0
    assert plan.duration == pytest.approx(stop_at_waypoints(W, lim).duration)


def test_seed_path_matches_the_stop_baseline_because_every_joint_reverses():
    # home → reach-out → home: every joint reverses at the reach-out, so it must stop there anyway
    lim = limits()
    W = np.array([HOME, REACH, HOME])
    smooth = plan_trajectory(W, lim).duration
    stop = plan_trajectory(W, lim, stop_at_waypoints=True).duration
    assert smooth == pytest.approx(stop, rel=0.01)


def test_repeated_waypoints_are_dropped_with_a_warning():
    plan = plan_trajectory(np.array([HOME, HOME, REACH, REACH, HOME]), limits())
    assert plan.waypoint_indices == [0, 2, 4]
    assert len(plan.warnings) == 2 and "waypoint 1 repeats waypoint 0" in plan.warnings[0]
    hold = plan_trajectory(np.array([HOME, HOME]), limits())
    assert hold.method == "hold" and hold.duration == 0.0 and "nothing to move" in hold.warnings[-1]


def test_jerk_limit_uses_ruckig_and_respects_every_limit():
    lim = limits(jerk=150.0)
    plan = plan_trajectory(SWEEP[:4], lim)
    assert plan.method == "ruckig"
    check = check_limits(plan.trajectory, lim, rate=1000.0)
    assert check.total == 0 and check.jerk == 0
    assert check.peak_jerk_ratio == pytest.approx(1.0, abs=2e-3)  # the jerk limit is used
    q = plan.trajectory.evaluate(plan.waypoint_times)[0]
    assert np.allclose(q, SWEEP[:4], atol=1e-6)
    no_jerk = plan_trajectory(SWEEP[:4], limits())
    assert plan.duration > no_jerk.duration  # a jerk limit can only slow it down


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(2, 6), st.integers(0, 10_000), st.floats(0.2, 1.0), st.floats(1.0, 15.0))
def test_random_waypoints_never_break_a_limit(k, seed, vscale, acc):
    rng = np.random.default_rng(seed)
    W = rng.uniform(LOWER, UPPER, size=(k, 7))
    lim = limits(vscale, acc)
    plan = plan_trajectory(W, lim)
    check = check_limits(plan.trajectory, lim, rate=1000.0)
    assert check.total == 0, check
    q, qd, _ = plan.trajectory.evaluate(plan.waypoint_times)
    assert np.allclose(q, W, atol=1e-8)
    assert np.allclose(qd[[0, -1]], 0.0, atol=1e-8)
    assert plan.duration <= plan_trajectory(W, lim, stop_at_waypoints=True).duration + 1e-9


def test_check_limits_catches_a_velocity_jump_between_samples():
    from robocfg.motion.trajectory import Trajectory

    class Jump(Trajectory):  # +v then −v with no deceleration: q̈ reads 0 everywhere
        duration = 1.0

        def _eval(self, t):
            v = np.where(t < 0.5004, 1.0, -1.0)[:, None] * np.ones((1, 7))
            q = np.where(t < 0.5004, t, 1.0008 - t)[:, None] * np.ones((1, 7)) + HOME
            return q, v, np.zeros_like(q)

    check = check_limits(Jump(), limits(), rate=1000.0)
    assert check.acceleration > 0 and check.velocity == 0
