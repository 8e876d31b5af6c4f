"""Grasp-frame conversion: the one formula every grasping command uses."""

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.config import catalog
from robocfg.config.types import AXIS_INDEX
from robocfg.kinematics.frames import (
    Grasp,
    ee_pose_from_grasp,
    grasp_rotation,
    tcp_from_ee,
    top_down_grasps,
)


@pytest.fixture(scope="module")
def panda_arm():
    return load_robot(catalog.find("robots", "panda")).config.arms[0]


def test_grasp_rotation_is_right_handed():
    R = grasp_rotation([0, 0, -1], [1, 0.2, 0.3])
    assert np.allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.isclose(np.linalg.det(R), 1.0)
    assert np.allclose(R[:, 0], [0, 0, -1])
    assert np.allclose(np.cross(R[:, 0], R[:, 1]), R[:, 2])


def test_ee_pose_puts_tcp_on_grasp_centre(panda_arm):
    rng = np.random.default_rng(0)
    for _ in range(20):
        R = grasp_rotation(rng.normal(size=3), rng.normal(size=3))
        g = Grasp(rng.normal(size=3), R, 0.04)
        T_ee = ee_pose_from_grasp(g, panda_arm)
        axis = AXIS_INDEX[panda_arm.ee_axis]
        # the EE approach axis is the grasp approach direction
        assert np.allclose(T_ee[:3, axis], g.approach(), atol=1e-12)
        assert np.allclose(tcp_from_ee(T_ee, panda_arm)[:3, 3], g.center, atol=1e-12)
        # standoff moves the TCP back along the approach
        T_pre = ee_pose_from_grasp(g, panda_arm, standoff=0.1)
        assert np.allclose(tcp_from_ee(T_pre, panda_arm)[:3, 3], g.center - 0.1 * g.approach(), atol=1e-12)


def test_top_down_grasp_closes_across_narrow_side():
    yaw = np.radians(30)
    grasps = top_down_grasps(np.zeros(3), yaw, (0.08, 0.03))  # narrow along the object's y
    for g in grasps:
        assert np.allclose(g.approach(), [0, 0, -1])
        assert np.isclose(abs(g.closing() @ [-np.sin(yaw), np.cos(yaw), 0]), 1.0)
        assert np.isclose(g.width, 0.03)
    assert np.allclose(grasps[0].closing(), -grasps[1].closing())
