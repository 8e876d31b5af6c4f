"""``placo`` IK backend with self-collision avoidance (Panda): answers never put two non-adjacent
links in collision, checked independently with PyBullet's ``getClosestPoints`` (convex hulls)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet as p
import pybullet_data
import pytest

from robocfg.checks import load_robot
from robocfg.kinematics.ik.common import residuals
from robocfg.kinematics.ik.placo_qp import PlacoSolver
from robocfg.kinematics.model import KinematicModel

PANDA = Path(__file__).parents[1] / "robocfg" / "data" / "robots" / "panda.yaml"
PENETRATION_TOL = 3e-3  # m: PyBullet reports ≈ 2 mm less than coal for the same hulls (its collision margin)


@pytest.fixture(scope="module")
def model() -> KinematicModel:
    return KinematicModel.from_robot(load_robot(PANDA))


@pytest.fixture(scope="module")
def solver(model: KinematicModel) -> PlacoSolver:
    s = model.solver("placo")
    assert s.field is not None and len(s.pair_names) >= 20  # avoidance is on by default
    return s


class BulletPanda:
    """The Panda in a DIRECT PyBullet client; ``pair_distances(q)`` over the solver's link pairs."""

    def __init__(self, model: KinematicModel, solver: PlacoSolver):
        self.cid = p.connect(p.DIRECT)
        self.body = p.loadURDF(str(Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"),
                               useFixedBase=True, physicsClientId=self.cid)
        link_of = {p.getBodyInfo(self.body, physicsClientId=self.cid)[0].decode(): -1}
        joint_of = {}
        for j in range(p.getNumJoints(self.body, physicsClientId=self.cid)):
            info = p.getJointInfo(self.body, j, physicsClientId=self.cid)
            link_of[info[12].decode()] = j
            joint_of[info[1].decode()] = j
        for name, value in model.locked.items():
            p.resetJointState(self.body, joint_of[name], value, physicsClientId=self.cid)
        self.arm = [joint_of[n] for n in model.joint_names]
        self.pairs = sorted({(link_of[a.rsplit("_", 1)[0]], link_of[b.rsplit("_", 1)[0]]) for a, b in solver.pair_names})

    def pair_distances(self, q: np.ndarray) -> list[float]:
        for j, v in zip(self.arm, q.tolist(), strict=True):
            p.resetJointState(self.body, j, v, physicsClientId=self.cid)
        out = []
        for a, b in self.pairs:
            pts = p.getClosestPoints(self.body, self.body, 1.0, a, b, physicsClientId=self.cid)
            out.append(min((pt[8] for pt in pts), default=1.0))
        return out

    def close(self) -> None:
        p.disconnect(self.cid)


@pytest.fixture(scope="module")
def bullet(model: KinematicModel, solver: PlacoSolver):
    b = BulletPanda(model, solver)
    yield b
    b.close()


def test_colliding_straightforward_answer_is_avoided(model: KinematicModel, solver: PlacoSolver, bullet) -> None:
    """Target = FK of a self-colliding configuration, seed = that configuration: pure IK returns the
    seed itself (in collision); with avoidance the answer is collision-free or not converged."""
    rng = np.random.default_rng(3)
    plain = PlacoSolver(model, self_collision=False)
    solved = 0
    cases = 0
    while cases < 4:
        q_col = rng.uniform(model.lower, model.upper)
        if min(bullet.pair_distances(q_col)) > -0.01:  # want a clear collision between non-adjacent links
            continue
        cases += 1
        T = model.fk(q_col)
        naive = plain.solve(T, q_col, time_budget=0.05)
        assert naive.converged and min(bullet.pair_distances(naive.q)) < 0  # the straightforward answer collides
        res = solver.solve(T, q_col, time_budget=0.3, rng=np.random.default_rng(cases))
        assert model.within_limits(res.q)
        if res.converged:
            solved += 1
            pe, re = residuals(model.fk(res.q), T)
            assert pe <= 1e-5 and re <= 1e-5
            assert min(bullet.pair_distances(res.q)) >= -PENETRATION_TOL
            assert solver.min_distance(res.q) >= 0.0
    assert solved >= 1  # these targets have collision-free answers on another branch


def test_collision_free_targets_still_reached(model: KinematicModel, solver: PlacoSolver, bullet) -> None:
    """Targets from collision-free configurations: reached to 1e-5 m / 1e-5 rad, answers collision-free."""
    rng = np.random.default_rng(7)
    n = failures = 0
    while n < 20:
        q = rng.uniform(model.lower, model.upper)
        if solver.min_distance(q) < 0.0:
            continue
        n += 1
        T = model.fk(q)
        res = solver.solve(T, model.mid, time_budget=0.3, rng=np.random.default_rng(n))
        if not res.converged:
            failures += 1
            continue
        pe, re = residuals(model.fk(res.q), T)
        assert pe <= 1e-5 and re <= 1e-5 and model.within_limits(res.q)
        assert min(bullet.pair_distances(res.q)) >= -PENETRATION_TOL
    assert failures <= 1, f"{failures}/{n} collision-free targets not reached"


def test_self_collision_can_be_turned_off(model: KinematicModel) -> None:
    s = PlacoSolver(model, self_collision=False)
    assert s.field is None and s.min_distance(model.home) == float("inf")
