"""Target motions: positions on the configured path, velocities, orientation modes, bad motion types."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pydantic import ValidationError

from robocfg.config.commands import FollowTargetParams, Motion
from robocfg.motion.targets import TargetMotion


def test_static_stays_at_the_centre():
    m = TargetMotion(Motion(type="static", center=[0.4, 0.1, 0.3]))
    assert np.allclose(m.position(0.0), [0.4, 0.1, 0.3]) and np.allclose(m.position(7.3), [0.4, 0.1, 0.3])
    assert np.allclose(m.velocity(2.0), 0.0) and m.end_time == 0.0


def test_circle_radius_period_plane_and_speed():
    m = TargetMotion(Motion(type="circle", center=[0.5, 0.0, 0.4], radius=0.1, period=4.0, plane="yz"))
    c = np.array([0.5, 0.0, 0.4])
    for t in np.linspace(0, 4, 17):
        p = m.position(t)
        assert abs(np.linalg.norm(p - c) - 0.1) < 1e-12 and abs(p[0] - 0.5) < 1e-12  # in the yz plane
    assert np.allclose(m.position(0.0), m.position(4.0))
    assert np.allclose(m.position(0.0), [0.5, 0.1, 0.4])
    assert abs(np.linalg.norm(m.velocity(1.3)[:3]) - 2 * math.pi * 0.1 / 4.0) < 1e-6


def test_figure8_passes_the_centre_twice_per_period():
    m = TargetMotion(Motion(type="figure8", center=[0.5, 0.0, 0.4], radius=0.1, period=4.0, plane="xy"))
    for t in (0.0, 2.0, 4.0):
        assert np.allclose(m.position(t), [0.5, 0.0, 0.4], atol=1e-12)
    assert abs(m.position(1.0)[0] - 0.6) < 1e-12  # half-width = radius along the first axis
    assert all(abs(m.position(t)[2] - 0.4) < 1e-12 for t in np.linspace(0, 4, 9))


def test_waypoints_timed_smooth_and_held():
    pts = [[0.4, 0.0, 0.3], [0.5, 0.2, 0.3], [0.5, 0.2, 0.5]]
    m = TargetMotion(Motion(type="waypoints", waypoints=pts, waypoint_times=[1.0, 2.0, 4.0]))
    for p, t in zip(pts, [1.0, 2.0, 4.0], strict=True):
        assert np.allclose(m.position(t), p)
        assert np.allclose(m.velocity(t)[:3], 0.0, atol=1e-4)  # rests at each waypoint
    assert np.allclose(m.position(0.2), pts[0]) and np.allclose(m.position(9.0), pts[-1])
    assert m.end_time == 4.0
    mid = m.position(1.5)
    assert np.allclose(mid, (np.array(pts[0]) + pts[1]) / 2)


def test_waypoints_loop_returns_to_the_first():
    m = TargetMotion(Motion(type="waypoints", waypoints=[[0.4, 0, 0.3], [0.5, 0, 0.3]], waypoint_times=[0.0, 1.0], loop=True))
    assert np.allclose(m.position(2.0), [0.4, 0, 0.3]) and m.end_time == math.inf


def test_following_orientation_swings_about_the_plane_normal():
    R0 = np.diag([1.0, -1.0, -1.0])
    m = TargetMotion(Motion(type="circle", plane="xy", period=4.0), R0, "following", math.radians(30))
    R = m.rotation(1.0)  # sin(π/2) = 1: full amplitude
    rel = R @ R0.T
    assert abs(math.degrees(math.acos((np.trace(rel) - 1) / 2)) - 30.0) < 1e-9
    assert np.allclose(rel @ [0, 0, 1], [0, 0, 1])  # about z, the xy plane's normal
    assert np.allclose(TargetMotion(Motion(type="circle"), R0).rotation(1.0), R0)  # fixed


def test_unknown_motion_type_lists_the_valid_ones():
    with pytest.raises(ValidationError) as e:
        FollowTargetParams.model_validate({"motion": {"type": "spiral"}})
    msg = str(e.value)
    for name in ("static", "waypoints", "circle", "figure8"):
        assert name in msg


def test_waypoint_motion_needs_points_and_matching_increasing_times():
    with pytest.raises(ValidationError):
        Motion(type="waypoints")
    with pytest.raises(ValidationError):
        Motion(type="waypoints", waypoints=[[0, 0, 0], [1, 0, 0]], waypoint_times=[1.0])
    with pytest.raises(ValidationError):
        Motion(type="waypoints", waypoints=[[0, 0, 0], [1, 0, 0]], waypoint_times=[1.0, 1.0])
