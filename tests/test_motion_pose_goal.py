"""PoseGoal decides convergence as the 4x4 pose's numpy errors do, whatever its own rounding."""

import math

import numpy as np
import pytest

from robocfg.geometry import axis_angle_matrix, pose_to_matrix, rotation_angle
from robocfg.geometry.rotation import matrix_to_quat
from robocfg.motion.pose_goal import PoseGoal


def _reference(T: np.ndarray, G: np.ndarray, ptol: float, rtol: float) -> bool:
    """The convergence test as ``ArmMover.converge`` made it from ``ee_pose()``."""
    dp = float(np.linalg.norm(T[:3, 3] - G[:3, 3]))
    return dp <= ptol and rotation_angle(T[:3, :3], G[:3, :3]) <= rtol


def _random_pose(rng: np.random.Generator) -> tuple[tuple[float, ...], tuple[float, ...]]:
    q = rng.normal(size=4)
    return tuple(rng.uniform(-1, 1, 3).tolist()), tuple((q / np.linalg.norm(q)).tolist())


def test_the_decision_is_the_reference_one_near_and_far_from_the_tolerances() -> None:
    rng = np.random.default_rng(0)
    decided = {True: 0, False: 0}
    for _ in range(4000):
        pos, quat = _random_pose(rng)
        T = pose_to_matrix(pos, quat)
        # goals around the pose: offsets at, just inside and just outside the tolerances, and far
        ptol, rtol = 0.005, 0.05
        scale = rng.choice([0.0, 0.5, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 1.0 - 1e-7, 1.0 + 1e-7, 2.0])
        G = T.copy()
        G[:3, 3] += ptol * scale * rng.choice([0.0, 1.0]) * np.array([1.0, 0.0, 0.0])
        G[:3, :3] = G[:3, :3] @ axis_angle_matrix(rng.normal(size=3), rtol * rng.choice([0.0, 0.5, 1.0 - 1e-9, 1.0,
                                                                                             1.0 + 1e-9, 3.0]))
        want = _reference(T, G, ptol, rtol)
        assert PoseGoal(G, ptol, rtol).reached(pos, quat) == want
        decided[want] += 1
    assert min(decided.values()) > 500  # both answers were exercised


def test_exact_ties_and_zero_tolerances_follow_the_reference() -> None:
    rng = np.random.default_rng(1)
    for _ in range(500):
        pos, quat = _random_pose(rng)
        T = pose_to_matrix(pos, quat)
        dp = float(np.linalg.norm(T[:3, 3] - (T[:3, 3] + [3e-3, 0, 0])))
        G = T.copy()
        G[0, 3] += 3e-3
        dr = rotation_angle(T[:3, :3], G[:3, :3])
        for ptol, rtol in ((dp, dr), (dp, 0.0), (np.nextafter(dp, 0.0), 1.0), (0.0, 0.0)):
            assert PoseGoal(G, ptol, rtol).reached(pos, quat) == _reference(T, G, ptol, rtol)


def test_errors_are_the_reference_ones_and_bad_quaternions_take_the_reference_path() -> None:
    G = pose_to_matrix([0.3, 0.1, 0.5], matrix_to_quat(axis_angle_matrix([0, 0, 1], 0.3)))
    goal = PoseGoal(G, 0.005, 0.05)
    pos, quat = (0.3, 0.1, 0.51), tuple(matrix_to_quat(axis_angle_matrix([0, 0, 1], 0.2)).tolist())
    dp, dr = goal.errors_at(pos, quat)
    assert dp == pytest.approx(0.01, abs=1e-12) and dr == pytest.approx(0.1, abs=1e-9)
    assert not goal.reached(pos, quat)
    assert goal.reached((0.3, 0.1, 0.5), tuple(matrix_to_quat(G[:3, :3]).tolist()))
    for bad in ((math.nan, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 0.0)):  # what ee_pose() refused, refused alike
        with pytest.raises(ValueError):
            pose_to_matrix((0.3, 0.1, 0.5), bad)
        with pytest.raises(ValueError):
            goal.reached((0.3, 0.1, 0.5), bad)
