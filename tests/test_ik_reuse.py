"""What the LM solver and the arm mover reuse instead of recomputing gives the same answers: the
residuals measured inside the descent are those a fresh FK gives, a seed inside the limits is
used as given (a copy), and the mover's remembered answers are the solver's own."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from robocfg.checks import load_robot
from robocfg.errors import RobocfgError
from robocfg.kinematics.ik.common import (
    LIMIT_TOL,
    check_seed,
    check_target,
    finish,
    into_limits,
    joints_at_limit,
    prepare,
)
from robocfg.kinematics.model import KinematicModel
from robocfg.motion.moves import ArmMover, bound_ik_by_iterations

ROBOTS = Path(__file__).parents[1] / "robocfg" / "data" / "robots"
UR5E = Path(__file__).parent / "data" / "ur5e_ik.yaml"  # joints spanning ±2π: wrapped


@pytest.fixture(scope="module", params=["panda", "ur5e"])
def model(request) -> KinematicModel:
    path = ROBOTS / "panda.yaml" if request.param == "panda" else UR5E
    return KinematicModel.from_robot(load_robot(path))


def _measured_again(model: KinematicModel, q: np.ndarray, T: np.ndarray, position_only: bool):
    fid = model.frame_id("ee")
    Mt = pin.SE3(T[:3, :3], T[:3, 3])
    return finish(model, "lm", q, Mt, fid, position_only, 1e-5, 1e-5, 0.0, 0, 0)


@pytest.mark.parametrize("position_only", [False, True])
def test_lm_residuals_are_those_of_a_fresh_fk(model: KinematicModel, position_only: bool) -> None:
    """Reachable and unreachable targets, seeds inside and outside the limits, with restarts: the
    reported residuals and convergence are bit for bit what FK of the answer gives."""
    rng = np.random.default_rng(3)
    solver = model.solver("lm")
    cases = 0
    for i in range(40):
        T = model.fk(rng.uniform(model.lower, model.upper), "ee")
        if i % 4 == 3:
            T[:3, 3] *= 3.0  # out of reach: the best of stalled descents comes back
        seed = rng.uniform(model.lower - 1.0, model.upper + 1.0) if i % 2 else rng.uniform(model.lower, model.upper)
        res = solver.solve(T, seed, frame="ee", time_budget=0.2, position_only=position_only,
                           rng=np.random.default_rng(i))
        again = _measured_again(model, res.q, T, position_only)
        assert (res.pos_err, res.rot_err, res.converged) == (again.pos_err, again.rot_err, again.converged)
        cases += res.converged
    assert 0 < cases < 40  # both kinds seen


def test_a_seed_inside_the_limits_is_used_as_given(model: KinematicModel) -> None:
    rng = np.random.default_rng(0)
    for _ in range(20):
        seed = rng.uniform(model.lower, model.upper)
        got = check_seed(model, seed)
        assert got is not seed and np.array_equal(got, seed)
        got[0] += 1.0  # a copy: the caller's seed is not changed
        assert not np.array_equal(got, seed)
    outside = model.upper + 0.5
    assert np.array_equal(check_seed(model, outside), into_limits(model, outside))
    with pytest.raises(Exception, match="NaN"):
        check_seed(model, np.full(model.nq, np.nan))
    _, q0, _, _ = prepare(model, np.eye(4), outside, "ee")
    assert model.within_limits(q0)


def test_a_rotation_checked_once_still_rejects_others(model: KinematicModel) -> None:
    """check_target skips the rotation check for the rotation it last accepted (a straight line's
    targets share one): any other rotation, and a non-finite translation, are still refused."""
    T = model.fk(model.home, "ee")
    assert np.array_equal(check_target(T), T) and check_target(T) is not T
    moved = T.copy()
    moved[:3, 3] += 0.1
    assert np.array_equal(check_target(moved), moved)  # the same rotation, accepted again
    for bad in (1.001, -1.0):  # scaled, reflected
        wrong = moved.copy()
        wrong[:3, :3] *= bad
        with pytest.raises(RobocfgError, match="not a rotation matrix"):
            check_target(wrong)
    moved[0, 3] = np.nan
    with pytest.raises(RobocfgError, match="NaN"):
        check_target(moved)
    with pytest.raises(RobocfgError, match="4x4"):
        check_target(T[:3])


def test_joints_at_limit_by_definition(model: KinematicModel) -> None:
    """The joints within LIMIT_TOL of a limit, wrapped joints never, as a plain reading of the limits."""
    rng = np.random.default_rng(5)
    lo, hi = model.lower, model.upper
    for _ in range(50):
        q = rng.uniform(lo, hi)
        pick = rng.integers(0, 4, model.nq)  # 0: inside, 1: at lower, 2: near upper, 3: just beyond the tolerance
        q = np.where(pick == 1, lo, q)
        q = np.where(pick == 2, hi - 0.5 * LIMIT_TOL, q)
        q = np.where(pick == 3, lo + 2 * LIMIT_TOL, q)
        want = [n for n, v, a, b, w in zip(model.joint_names, q, lo, hi, model.wrap, strict=True)
                if not w and (v - a <= LIMIT_TOL or b - v <= LIMIT_TOL)]
        assert joints_at_limit(model, q) == want
    if model.any_wrap:  # a wrapped joint at its limit is not reported
        k = int(np.flatnonzero(model.wrap)[0])
        q = model.home.copy()
        q[k] = hi[k]
        assert model.joint_names[k] not in joints_at_limit(model, q)


class _World:
    dt, t = 1 / 240, 0.0


def test_the_mover_remembers_answers_by_exact_inputs() -> None:
    model = KinematicModel.from_robot(load_robot(ROBOTS / "panda.yaml"))
    bound_ik_by_iterations(model)
    solved = []
    real = model.ik

    def counted(*a, **k):
        solved.append(1)
        return real(*a, **k)

    model.ik = counted  # type: ignore[method-assign]
    mover = ArmMover(_World(), None, model, None)  # type: ignore[arg-type]
    q0 = model.home.copy()
    T = model.fk(q0, "ee")
    T[:3, 3] += [0.05, -0.03, 0.02]
    first = mover.ik(T, q0)
    again = mover.ik(T.copy(), q0.copy())
    assert len(solved) == 1
    assert np.array_equal(first.q, again.q) and first.q is not again.q
    assert np.array_equal(first.q, real(T, seed_q=q0, frame="ee").q)  # the solver's own answer
    np.testing.assert_allclose(model.fk(first.q, "ee"), T, atol=1e-5)
    again.q[0] += 1.0  # a caller changing its copy changes nothing remembered
    assert np.array_equal(mover.ik(T, q0).q, first.q)
    seed = q0.copy()
    seed[0] += 1e-12  # any other seed is a new question
    mover.ik(T, seed)
    assert len(solved) == 2
