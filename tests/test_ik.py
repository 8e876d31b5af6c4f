"""IK backends: answers whose FK really matches the target, within limits; bad input; registry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.errors import NotFound, RobocfgError
from robocfg.kinematics.ik import IKResult, get_backend, known_backends, register
from robocfg.kinematics.ik.common import residuals
from robocfg.kinematics.model import KinematicModel

PANDA = Path(__file__).parents[1] / "robocfg" / "data" / "robots" / "panda.yaml"
N_TARGETS = {"lm": 50, "pink": 20, "placo": 20}
BUDGET = {"lm": 0.05, "pink": 0.3, "placo": 0.3}  # s; generous: CI machines are slow


@pytest.fixture(scope="module")
def model() -> KinematicModel:
    import pinocchio as pin

    base = np.eye(4)
    base[:3, :3] = pin.rpy.rpyToMatrix(0.0, 0.0, 0.7)
    base[:3, 3] = [0.3, -0.2, 0.1]
    return KinematicModel.from_robot(load_robot(PANDA), base_pose=base)


def _check_answer(model: KinematicModel, res: IKResult, T: np.ndarray, frame: str, tol: float = 1e-5) -> None:
    pe, re = residuals(model.fk(res.q, frame), T)
    assert res.converged, f"not converged: {res.pos_err:.2e} m, {res.rot_err:.2e} rad"
    assert pe <= tol and re <= tol, f"FK of the answer is off by {pe:.2e} m, {re:.2e} rad"
    assert res.pos_err == pytest.approx(pe, abs=1e-9)
    assert model.within_limits(res.q), f"answer outside the limits: {res.q}"


@pytest.mark.parametrize("backend", ["lm", "pink", "placo"])
def test_random_reachable_targets(model: KinematicModel, backend: str) -> None:
    rng = np.random.default_rng(11)
    n = N_TARGETS[backend]
    failures = 0
    for i in range(n):
        frame = "tcp" if i % 2 == 0 else "ee"
        T = model.fk(rng.uniform(model.lower, model.upper), frame)
        res = model.ik(T, seed_q=model.mid, frame=frame, backend=backend, time_budget=BUDGET[backend],
                       rng=np.random.default_rng(i))
        if not res.converged:
            failures += 1
            continue
        _check_answer(model, res, T, frame)
    assert failures <= (0 if backend == "lm" else 2), f"{failures}/{n} did not converge"


def test_lm_is_deterministic_and_reports(model: KinematicModel) -> None:
    T = model.fk(model.home + 0.3)
    a = model.ik(T, time_budget=0.05)
    b = model.ik(T, time_budget=0.05)
    np.testing.assert_array_equal(a.q, b.q)
    assert a.backend == "lm" and a.iterations >= 1 and a.time_s > 0
    assert isinstance(a.joints_at_limit, list)


def test_position_only(model: KinematicModel) -> None:
    target = model.fk(model.home)
    target[:3, 3] += [0.05, -0.1, 0.02]
    target[:3, :3] = np.diag([1.0, -1.0, -1.0]) @ target[:3, :3]  # orientation the arm cannot hold there
    for backend in ("lm", "pink", "placo"):
        res = model.ik(target, backend=backend, position_only=True, time_budget=0.3)
        assert res.converged and res.rot_err == 0.0
        assert np.linalg.norm(model.fk(res.q)[:3, 3] - target[:3, 3]) <= 1e-5


@pytest.mark.parametrize("backend", ["lm", "pink", "placo"])
def test_unreachable_target_returns_best_residual(model: KinematicModel, backend: str) -> None:
    T = model.fk(model.home)
    T[:3, 3] = model.base_pose[:3, 3] + [3.0, 0.0, 0.5]  # 3 m away: beyond the Panda's reach
    budget = 0.02
    res = model.ik(T, backend=backend, time_budget=budget)
    assert not res.converged
    assert 1.5 < res.pos_err < 3.0  # the best residual, not garbage
    assert res.time_s < budget + 0.2  # bounded by the budget (plus one iteration), never a hang
    assert model.within_limits(res.q)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_nan_or_inf_target_raises(model: KinematicModel, bad: float) -> None:
    T = model.fk(model.home)
    T[0, 3] = bad
    for backend in ("lm", "pink", "placo"):
        with pytest.raises(RobocfgError, match="NaN or infinite"):
            model.ik(T, backend=backend)


def test_malformed_target_and_seed(model: KinematicModel) -> None:
    T = model.fk(model.home)
    with pytest.raises(RobocfgError, match="4x4"):
        model.ik(T[:3])
    T2 = T.copy()
    T2[:3, :3] *= 2.0
    with pytest.raises(RobocfgError, match="rotation"):
        model.ik(T2)
    with pytest.raises(RobocfgError, match="seed_q"):
        model.ik(T, seed_q=np.zeros(model.nq - 1))
    with pytest.raises(NotFound, match="frame"):
        model.ik(T, frame="no_such_link")


def test_registry() -> None:
    assert {"lm", "pink", "placo"} <= set(known_backends())
    with pytest.raises(NotFound, match="known: lm, pink, placo"):
        get_backend("trac")
    with pytest.raises(RobocfgError, match="already registered"):
        register("lm")(object)


def test_ur5e_wide_joints_are_wrapped_near_the_seed() -> None:
    """UR5e joints span ±2π: answers stay within limits and take the 2π-equivalent nearest the seed."""
    import math

    model = KinematicModel.from_robot(load_robot(Path(__file__).parent / "data" / "ur5e_ik.yaml"))
    assert model.wrap.sum() >= 5
    rng = np.random.default_rng(5)
    for i in range(30):
        T = model.fk(rng.uniform(model.lower, model.upper), "ee")
        seed = rng.uniform(model.lower, model.upper)
        res = model.ik(T, seed_q=seed, frame="ee", time_budget=0.05, rng=np.random.default_rng(i))
        _check_answer(model, res, T, "ee")
        dist = np.abs(res.q - seed)
        for shift in (2 * math.pi, -2 * math.pi):  # no 2π-equivalent within the limits is nearer the seed
            alt = res.q + shift
            inside = (alt >= model.lower) & (alt <= model.upper) & model.wrap
            assert np.all(dist[inside] <= np.abs(alt - seed)[inside] + 1e-9)


CONTINUOUS_URDF = """<?xml version="1.0"?>
<robot name="yaw_arm">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l3"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="yaw" type="continuous"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/></joint>
  <joint name="shoulder" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0"/><axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.4 0 0"/><axis xyz="0 1 0"/><limit lower="-2.5" upper="2.5" effort="10" velocity="2"/></joint>
</robot>
"""

CONTINUOUS_YAML = """schema_version: 1
name: yaw_arm
urdf: yaw_arm.urdf
arms:
  - joints: [yaw, shoulder, elbow]
    base_link: base
    ee_link: l3
    tcp_offset: 0.3
    ee_axis: x
    R_ee_graspnet: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    home: [0.0, 0.3, 0.6]
"""


def test_continuous_joint_is_wrapped_and_position_only_works(tmp_path) -> None:
    """A 3-DOF arm with a continuous base joint: position-only IK, answers within (−π, π]."""
    (tmp_path / "yaw_arm.urdf").write_text(CONTINUOUS_URDF)
    (tmp_path / "yaw_arm.yaml").write_text(CONTINUOUS_YAML)
    model = KinematicModel.from_robot(load_robot(tmp_path / "yaw_arm.yaml"))
    assert model.wrap.tolist() == [True, False, False]
    assert model.lower[0] == pytest.approx(-np.pi) and model.upper[0] == pytest.approx(np.pi)
    rng = np.random.default_rng(2)
    for i in range(20):
        T = model.fk(rng.uniform(model.lower, model.upper))
        seed = model.home.copy()
        seed[0] = 3.0  # near +π: the answer may need to cross ±π
        res = model.ik(T, seed_q=seed, position_only=True, time_budget=0.05, rng=np.random.default_rng(i))
        assert res.converged
        assert np.linalg.norm(model.fk(res.q)[:3, 3] - T[:3, 3]) <= 1e-5
        assert model.within_limits(res.q)
