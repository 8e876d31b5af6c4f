"""robocfg.geometry: rotation and pose conversions, checked against PyBullet's own maths."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest

from robocfg.geometry import (
    axis_angle_matrix,
    euler_deg_to_quat_xyzw,
    matrix_to_pose,
    matrix_to_quat,
    pose_matrix,
    pose_to_matrix,
    quat_to_matrix,
    rotation_angle,
    rpy_matrix,
)


def _random_quats(n: int, seed: int = 0) -> np.ndarray:
    q = np.random.default_rng(seed).normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_euler_deg_matches_pybullet():
    rng = np.random.default_rng(0)
    for rpy in rng.uniform(-180, 180, size=(50, 3)):
        ours = np.asarray(euler_deg_to_quat_xyzw(list(rpy)))
        ref = np.asarray(p.getQuaternionFromEuler(np.radians(rpy)))
        assert min(np.abs(ours - ref).max(), np.abs(ours + ref).max()) < 1e-12


def test_rpy_is_rz_ry_rx():
    r, pt, y = np.radians([30.0, -20.0, 75.0])
    Rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    Ry = np.array([[np.cos(pt), 0, np.sin(pt)], [0, 1, 0], [-np.sin(pt), 0, np.cos(pt)]])
    Rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    assert np.allclose(rpy_matrix(r, pt, y), Rz @ Ry @ Rx, atol=1e-12)
    R = np.asarray(p.getMatrixFromQuaternion(euler_deg_to_quat_xyzw([30.0, -20.0, 75.0]))).reshape(3, 3)
    assert np.allclose(R, Rz @ Ry @ Rx, atol=1e-12)


def test_quat_to_matrix_matches_pybullet_and_round_trips():
    for q in _random_quats(50):
        R = quat_to_matrix(q)
        assert np.allclose(R, np.asarray(p.getMatrixFromQuaternion(q.tolist())).reshape(3, 3), atol=1e-12)
        back = matrix_to_quat(R)
        assert back[3] >= 0.0  # one sign per rotation: the same rotation gives the same numbers
        assert min(np.abs(back - q).max(), np.abs(back + q).max()) < 1e-12


def test_axis_angle_matches_pybullet():
    rng = np.random.default_rng(1)
    for axis, angle in zip(rng.normal(size=(20, 3)), rng.uniform(-np.pi, np.pi, 20), strict=True):
        ref = p.getQuaternionFromAxisAngle((axis / np.linalg.norm(axis)).tolist(), float(angle))
        assert np.allclose(axis_angle_matrix(axis * 3.0, angle), quat_to_matrix(ref), atol=1e-12)


def test_rotation_angle():
    R = axis_angle_matrix([0.0, 1.0, 1.0], 0.7)
    assert rotation_angle(np.eye(3), R) == pytest.approx(0.7, abs=1e-12)
    assert rotation_angle(R, R) == pytest.approx(0.0, abs=1e-7)
    assert rotation_angle(np.eye(3), axis_angle_matrix([1.0, 0.0, 0.0], np.pi)) == pytest.approx(np.pi)


def test_pose_round_trip_and_config_pose():
    from robocfg.config.types import Pose

    T = pose_to_matrix([0.1, -0.2, 0.3], euler_deg_to_quat_xyzw([10.0, 20.0, 30.0]))
    pos, quat = matrix_to_pose(T)
    assert np.allclose(pose_to_matrix(pos, quat), T, atol=1e-12)
    assert np.allclose(pose_matrix(Pose(position=[0.1, -0.2, 0.3], euler_deg=[10.0, 20.0, 30.0])), T, atol=1e-12)


def test_closed_forms_match_scipy():
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(2)
    for rpy in rng.uniform(-np.pi, np.pi, size=(30, 3)):
        assert np.allclose(rpy_matrix(*rpy), Rotation.from_euler("xyz", rpy).as_matrix(), atol=1e-12)
    for axis, angle in zip(rng.normal(size=(30, 3)), rng.uniform(-4, 4, 30), strict=True):
        ref = Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle).as_matrix()
        assert np.allclose(axis_angle_matrix(axis, angle), ref, atol=1e-12)


def test_quat_to_matrix_gives_scipys_bits_for_one_quaternion():
    """The closed form used for single quaternions is scipy's arithmetic: the same bits, so
    simulated runs (and golden reports) do not change with it; batches still go to scipy."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(3)
    qs = rng.normal(size=(3000, 4))
    qs[::2] /= np.linalg.norm(qs[::2], axis=1, keepdims=True)
    qs[::7] = [0.0, 0.0, 0.0, 1.0] + rng.normal(size=(len(qs[::7]), 4)) * 1e-9
    for q in qs:
        assert np.array_equal(quat_to_matrix(q), Rotation.from_quat(q).as_matrix())
    assert np.array_equal(quat_to_matrix(qs[:5]), Rotation.from_quat(qs[:5]).as_matrix())
    with pytest.raises(ValueError):
        quat_to_matrix([0.0, 0.0, 0.0, 0.0])


def test_euler_deg_to_quat_gives_scipys_bits():
    """The closed form is scipy's arithmetic: the same bits (signed zeros included), so task
    poses, simulated runs and golden reports do not change with it."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(5)
    angles = np.vstack([rng.uniform(-400.0, 400.0, size=(3000, 3)), rng.integers(-4, 5, size=(500, 3)) * 45.0,
                        [[0.0, 0.0, 0.0], [-0.0, 0.0, -0.0], [180.0, 90.0, -90.0]]])
    for rpy in angles:
        ours = np.array(euler_deg_to_quat_xyzw(list(rpy)))
        theirs = Rotation.from_euler("xyz", rpy, degrees=True).as_quat()
        assert ours.tobytes() == theirs.tobytes(), rpy
    assert all(type(v) is float for v in euler_deg_to_quat_xyzw([10, 20, 30]))
