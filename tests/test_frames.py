"""Grasp-frame conversion: the one formula every grasping command uses."""

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.config import catalog
from robocfg.config.types import AXIS_INDEX
from robocfg.kinematics.frames import (
    Grasp,
    ee_pose_from_grasp,
    ee_rotation,
    grasp_rotation,
    half_turn,
    tcp_from_ee,
    tool_R_ee,
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


def _robot_arms():
    return [(name, arm) for name, path in catalog.available("robots").items() for arm in load_robot(path).config.arms]


def test_a_tool_orientation_is_one_tool_pose_on_every_robot():
    """``orientation_frame: tool``: tool z = approach (grasp x), tool y = closing (grasp y), whatever
    the robot's ee_link frame, for every built-in arm and a Z1-like arm approaching along ee x."""
    from robocfg.geometry import euler_deg_to_quat_xyzw, quat_to_matrix

    arms = [arm for _, arm in _robot_arms()]
    panda = load_robot(catalog.find("robots", "panda")).config.arms[0]
    z1_like = panda.model_copy(update={"ee_axis": "x", "R_ee_graspnet": [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]})
    rng = np.random.default_rng(0)
    rotations = [quat_to_matrix(euler_deg_to_quat_xyzw([180.0, 0.0, 0.0]))]
    rotations += [quat_to_matrix(euler_deg_to_quat_xyzw(list(rng.uniform(-180, 180, 3)))) for _ in range(5)]
    for arm in [*arms, z1_like]:
        for R_tool in rotations:
            R_ee = ee_rotation(R_tool, arm, "tool")
            R_grasp = R_ee @ np.asarray(arm.R_ee_graspnet).T
            assert np.allclose(R_grasp[:, 0], R_tool[:, 2], atol=1e-12)  # approach = tool z
            assert np.allclose(R_grasp[:, 1], R_tool[:, 1], atol=1e-12)  # closing = tool y
            assert np.allclose(R_ee[:, AXIS_INDEX[arm.ee_axis]], R_tool[:, 2], atol=1e-12)
            assert np.array_equal(ee_rotation(R_tool, arm, "ee_link"), R_tool)
    down = rotations[0]
    assert np.array_equal(ee_rotation(down, panda, "tool"), down)  # the Panda's hand frame is its tool frame
    assert np.array_equal(tool_R_ee(panda), np.eye(3))
    assert ee_rotation(down, z1_like, "tool")[2, 0] == pytest.approx(-1.0)  # Z1: approach (ee x) straight down
    assert abs(ee_rotation(down, z1_like, "ee_link")[2, 0]) < 1e-12  # the same angles on the link: horizontal


def test_half_turn_turns_about_the_tool_axis(panda_arm):
    R = grasp_rotation([0, 0, -1], [0.3, 1.0, 0.0]) @ np.asarray(panda_arm.R_ee_graspnet)
    H = half_turn(R, panda_arm)
    assert np.allclose(H[:, 2], R[:, 2]) and np.allclose(H[:, :2], -R[:, :2])
    assert np.isclose(np.linalg.det(H), 1.0)


def _ee_pose_from_grasp_arrays(grasp, arm, standoff=0.0):
    """ee_pose_from_grasp as numpy arrays compute it (the code before its Python-float rewrite)."""
    from robocfg.kinematics import frames

    R_ee = grasp.rotation @ np.asarray(arm.R_ee_graspnet, float)
    tcp = np.asarray(grasp.center, float) - standoff * grasp.approach()
    tcp = tcp - frames.grasp_side_shift(arm, grasp.width) * grasp.closing()
    T = np.eye(4)
    T[:3, :3] = R_ee
    T[:3, 3] = tcp - arm.tcp_offset * R_ee[:, AXIS_INDEX[arm.ee_axis]]
    return T


def test_grasp_rotation_in_floats_has_the_arrays_bits():
    """The Python-float path gives numpy's bits: random directions over six decades, lists of ints,
    near-parallel pairs; a zero approach and other shapes take the arrays' own path."""
    from robocfg.kinematics.frames import _grasp_rotation_arrays

    rng = np.random.default_rng(7)
    for i in range(20000):
        a = rng.normal(size=3) * 10.0 ** rng.integers(-3, 3)
        c = rng.normal(size=3) * 10.0 ** rng.integers(-3, 3)
        if i % 5 == 0:
            c = a * rng.normal() + rng.normal(size=3) * 1e-6  # nearly parallel: the orthogonalisation matters
        if i % 7 == 0:
            a, c = np.round(a), np.round(c)  # axis-like directions
        try:
            want = _grasp_rotation_arrays(a, c)
        except ValueError:
            with pytest.raises(ValueError, match="parallel"):
                grasp_rotation(a, c)
            continue
        assert grasp_rotation(a, c).tobytes() == want.tobytes()
        assert grasp_rotation(list(a), tuple(c)).tobytes() == want.tobytes()
    assert grasp_rotation([0, 0, -1], [1, 2, 0]).tobytes() == _grasp_rotation_arrays([0, 0, -1], [1, 2, 0]).tobytes()
    with np.errstate(invalid="ignore", divide="ignore"):
        assert np.isnan(grasp_rotation([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])).all()  # as numpy: NaN, not an error
    with pytest.raises(ValueError, match="parallel"):
        grasp_rotation([0, 0, 1], [0, 0, 2])


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_ee_pose_from_grasp_in_floats_has_the_arrays_bits(panda_arm, monkeypatch, axis):
    """The EE pose's Python-float part (after numpy's R_ee product) gives the arrays' bits: random
    grasps, stand-offs and side shifts (a one-jaw gripper's), every ee_axis."""
    from robocfg.kinematics import frames

    rng = np.random.default_rng(3)
    arm = panda_arm.model_copy(update={"ee_axis": axis, "tcp_offset": float(rng.uniform(0.05, 0.2))})
    shifts = iter(rng.normal(size=4000) * 0.02)
    shift = [0.0]
    monkeypatch.setattr(frames, "grasp_side_shift", lambda arm, width: shift[0])
    for i in range(2000):
        shift[0] = 0.0 if i % 3 == 0 else float(next(shifts))
        R = grasp_rotation(rng.normal(size=3), rng.normal(size=3))
        g = Grasp(rng.normal(size=3) * 10.0 ** rng.integers(-2, 1), R, 0.04)
        standoff = 0.0 if i % 4 == 0 else float(rng.uniform(0.0, 0.3))
        assert ee_pose_from_grasp(g, arm, standoff).tobytes() == _ee_pose_from_grasp_arrays(g, arm, standoff).tobytes()
