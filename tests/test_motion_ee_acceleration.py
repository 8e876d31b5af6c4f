"""The EE acceleration bound that spares a timed move its 41-sample measure
(robocfg.motion.ee_acceleration, robocfg.kinematics.lever_arms): the lever arms are the URDF's
offsets summed down the chain and bound every Jacobian column, the bound is above the EE's
acceleration sampled densely, and the factor is the measured one whenever the bound is not enough."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from _sim_helpers import PANDA, ROOT

from robocfg.checks import load_robot
from robocfg.kinematics.lever_arms import lever_arms
from robocfg.kinematics.model import KinematicModel
from robocfg.motion import ee_acceleration as ea
from robocfg.motion.limits import make_limits
from robocfg.motion.minjerk_path import MinJerkPath

UR5E = ROOT / "robocfg" / "data" / "robots" / "ur5e_robotiq_2f85.yaml"


@pytest.fixture(scope="module", params=[PANDA, UR5E], ids=["panda", "ur5e"])
def kin(request):
    return KinematicModel.from_robot(load_robot(request.param))


def _limits(model: KinematicModel):
    n = model.nq
    return make_limits([f"j{i}" for i in range(n)], model.lower, model.upper, np.full(n, 2.0), np.full(n, 5.0))


def _measured(model: KinematicModel, traj, a_max: float, samples: int = ea.ACCEL_SAMPLES) -> tuple[float, float]:
    """(peak second difference over h², m/s²; the factor from it) at ``samples`` instants."""
    t = np.linspace(0.0, traj.duration, samples)
    P = model.fk_positions(traj.positions(t), "ee")
    peak = float(np.linalg.norm(np.diff(P, 2, axis=0), axis=1).max()) / (t[1] - t[0]) ** 2
    return peak, max(1.0, math.sqrt(peak / max(a_max, ea.MIN_ACCELERATION)))


def test_panda_lever_arms_are_its_urdf_offsets_summed_down_the_chain():
    # panda_link8 (the ee_link) is 0.107 m past joint 7; joint 7 is 0.088 m past joint 6 (at
    # joint 5's origin); joint 5 is |(-0.0825, 0.384, 0)| past joint 4, 0.0825 past joint 3, 0.316
    # past joint 2, which sits at joint 1's origin
    levers = KinematicModel.from_robot(load_robot(PANDA)).lever_arms("ee")
    j5 = 0.107 + 0.088 + math.hypot(0.0825, 0.384)
    expected = [j5 + 0.0825 + 0.316, j5 + 0.0825 + 0.316, j5 + 0.0825, j5, 0.195, 0.195, 0.107]
    assert levers == pytest.approx(expected, abs=1e-9)


def test_lever_arms_bound_every_jacobian_column(kin):
    levers = np.array(kin.lever_arms("ee"))
    rng = np.random.default_rng(3)
    worst = np.zeros(kin.nq)
    for _ in range(300):
        J = kin.jacobian(rng.uniform(kin.lower, kin.upper), "ee")
        worst = np.maximum(worst, np.linalg.norm(J[:3], axis=0))
    assert np.all(worst <= levers + 1e-12)
    assert worst[0] > 0.5 * levers[0]  # a bound, not a wild one


def test_no_lever_arms_for_a_prismatic_joint_on_the_chain():
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "turn")
    j2 = model.addJoint(j1, pin.JointModelPZ(), pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0])), "lift")
    fid = model.addFrame(pin.Frame("tool", j2, 0, pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1])), pin.FrameType.OP_FRAME))
    assert lever_arms(model, fid) is None
    fid1 = model.addFrame(pin.Frame("on_turn", j1, 0, pin.SE3(np.eye(3), np.array([0.2, 0.0, 0.0])), pin.FrameType.OP_FRAME))
    assert lever_arms(model, fid1) == (0.2, 0.0)  # the prismatic joint is off that frame's chain


def test_bound_is_above_the_densely_sampled_acceleration(kin):
    rng = np.random.default_rng(11)
    limits = _limits(kin)
    for k in (2, 3, 4, 6, 6, 6):
        W = [rng.uniform(kin.lower, kin.upper) * 0.7]
        for _ in range(k - 1):
            W.append(W[-1] + rng.normal(0.0, 0.3, kin.nq))
        traj = MinJerkPath(np.array(W), limits)
        d1, d2 = traj.path_bounds
        bound = ea.acceleration_bound(kin.lever_arms("ee"), d1, d2, traj.duration)
        peak, _ = _measured(kin, traj, 1.0, samples=4001)
        assert peak <= bound


def test_factor_is_one_unmeasured_when_the_bound_suffices_and_the_measured_one_otherwise(kin, monkeypatch):
    rng = np.random.default_rng(5)
    q0 = rng.uniform(kin.lower, kin.upper) * 0.5
    traj = MinJerkPath(np.array([q0, q0 + 0.4, q0 + np.linspace(0.1, 0.6, kin.nq)]), _limits(kin))
    peak, _ = _measured(kin, traj, 1.0)
    measures = []
    fk_positions = KinematicModel.fk_positions

    def counted(self, qs, frame="tcp"):
        measures.append(len(qs))
        return fk_positions(self, qs, frame)

    monkeypatch.setattr(KinematicModel, "fk_positions", counted)
    assert ea.stretch_factor(kin, traj, 1e3 * peak) == 1.0
    assert measures == []  # the bound answered
    for a_max in (0.3 * peak, 0.9 * peak, 1.1 * peak):  # the bound is not enough: measured, the same factor
        assert ea.stretch_factor(kin, traj, a_max) == _measured(kin, traj, a_max)[1]
    assert measures == [ea.ACCEL_SAMPLES] * 6
    assert ea.stretch_factor(kin, traj, 0.3 * peak) > 1.0


def test_bound_is_the_docstrings_sum():
    rng = np.random.default_rng(2)
    for n in (1, 6, 7):
        R, d1, d2 = rng.uniform(0, 1, n), rng.uniform(0, 2, n), rng.uniform(0, 3, n)
        T = rng.uniform(0.2, 2.0)
        v, a = d1 * 1.875 / T, d2 * (1.875 / T) ** 2 + d1 * (10 / math.sqrt(3)) / T**2
        expected = R @ a + v @ np.minimum.outer(R, R) @ v
        assert ea.acceleration_bound(tuple(R.tolist()), d1.tolist(), d2.tolist(), T) == pytest.approx(expected, rel=1e-12)
