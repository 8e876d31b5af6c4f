"""Every IK backend honours the iteration budget of the IKSolver protocol: with
``max_total_iter`` set, a query stops after that many iterations (restarts included) however
large its time budget, and the same query gives the same answer."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.kinematics.ik import IKSolver, known_backends
from robocfg.kinematics.model import KinematicModel

PANDA = Path(__file__).parents[1] / "robocfg" / "data" / "robots" / "panda.yaml"
BUDGET = 60  # iterations over all restarts


@pytest.fixture(scope="module")
def model() -> KinematicModel:
    return KinematicModel.from_robot(load_robot(PANDA))


@pytest.mark.parametrize("backend", ["lm", "pink", "placo"])
def test_iteration_budget_bounds_an_unreachable_query(model: KinematicModel, backend: str) -> None:
    assert backend in known_backends()
    solver: IKSolver = model.solver(backend)
    solver.max_total_iter = BUDGET
    try:
        target = model.fk(model.mid, "ee")
        target[:3, 3] += [3.0, 0.0, 0.0]  # 3 m beyond reach: every restart fails
        answers = [model.ik(target, model.mid, frame="ee", backend=backend, time_budget=60.0) for _ in range(2)]
    finally:
        solver.max_total_iter = None
    for res in answers:
        assert not res.converged
        assert 0 < res.iterations <= BUDGET
        assert res.restarts >= 1  # the budget, not one descent, ended the search
    assert np.array_equal(answers[0].q, answers[1].q)
    assert answers[0].iterations == answers[1].iterations


@pytest.mark.parametrize("backend", ["lm", "pink", "placo"])
def test_reachable_query_converges_within_the_budget(model: KinematicModel, backend: str) -> None:
    solver = model.solver(backend)
    solver.max_total_iter = 400
    try:
        q_goal = model.mid + 0.3
        res = model.ik(model.fk(q_goal, "ee"), model.mid, frame="ee", backend=backend, time_budget=60.0)
    finally:
        solver.max_total_iter = None
    assert res.converged and res.iterations <= 400
    assert res.pos_err <= 1e-5


def test_a_backend_added_as_the_architecture_recipe_says(model: KinematicModel) -> None:
    """docs/architecture.md, "Add an IK backend": a class with name / clock / max_total_iter /
    solve built on prepare, search and finish, registered by name, is used through model.ik."""
    import math
    from time import perf_counter

    import pinocchio as pin

    from robocfg.kinematics.ik import registry
    from robocfg.kinematics.ik.common import finish, into_limits, prepare, search

    class GaussNewton:
        name = "gauss-newton-test"
        clock = staticmethod(perf_counter)

        def __init__(self, km: KinematicModel, max_total_iter: int | None = None):
            self.km, self.max_total_iter = km, max_total_iter

        def solve(self, target, seed_q, frame="tcp", time_budget=0.02, position_only=False, rng=None):
            t0, km = perf_counter(), self.km
            _, q0, fid, Mt = prepare(km, target, seed_q, frame)

            def descend(q, deadline, cap):
                n, s = (30 if cap is None else min(30, cap)), math.inf
                for it in range(1, n + 1):
                    pin.forwardKinematics(km.model, km.data, q)
                    err = pin.log6(pin.updateFramePlacement(km.model, km.data, fid).actInv(Mt)).vector
                    s = float(np.linalg.norm(err))
                    if s < 1e-9:
                        return True, it, s, q
                    J = pin.computeFrameJacobian(km.model, km.data, q, fid, pin.LOCAL)
                    q = into_limits(km, q + np.linalg.lstsq(J, err, rcond=None)[0])
                return False, n, s, q

            best, iters, restarts = search(km, descend, q0, self.clock() + time_budget, rng, self.clock,
                                           self.max_total_iter)
            return finish(km, self.name, best, Mt, fid, position_only, 1e-5, 1e-5, t0, iters, restarts)

    registry.register(GaussNewton.name)(GaussNewton)
    try:
        assert GaussNewton.name in known_backends()
        fresh = KinematicModel.from_robot(load_robot(PANDA))
        fresh.solver(GaussNewton.name).max_total_iter = 200
        target = fresh.fk(fresh.mid + 0.2, "ee")
        res = fresh.ik(target, fresh.mid, frame="ee", backend=GaussNewton.name, time_budget=60.0)
        assert res.converged and res.backend == GaussNewton.name and res.iterations <= 200
    finally:
        registry._REGISTRY.pop(GaussNewton.name, None)


class _LoadedClock:
    """A clock on a machine so loaded that a second passes between any two readings."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        self.t += 1.0
        return self.t


@pytest.mark.parametrize("backend", ["lm", "pink", "placo"])
def test_with_an_iteration_budget_the_clock_ends_no_search(model: KinematicModel, backend: str) -> None:
    """Machine load must not change an answer: with ``max_total_iter`` set, a clock that jumps a
    second per reading (far past the 0.2 s budget) gives the same answer as the real clock."""
    solver = model.solver(backend)
    target = model.fk(model.mid, "ee")
    target[:3, 3] += [3.0, 0.0, 0.0]  # unreachable: only the budget ends the search
    reachable = model.fk(model.mid + 0.3, "ee")
    solver.max_total_iter = BUDGET
    try:
        quiet = [model.ik(T, model.mid, frame="ee", backend=backend, time_budget=0.2) for T in (target, reachable)]
        solver.clock = _LoadedClock()
        loaded = [model.ik(T, model.mid, frame="ee", backend=backend, time_budget=0.2) for T in (target, reachable)]
    finally:
        solver.max_total_iter = None
        del solver.clock  # back to the class's clock
    for a, b in zip(quiet, loaded, strict=True):
        assert a.iterations == b.iterations and a.restarts == b.restarts
        assert np.array_equal(a.q, b.q)
    assert loaded[0].iterations == BUDGET and loaded[0].restarts >= 1


def test_lm_first_descent_ignores_a_spent_time_budget(model: KinematicModel) -> None:
    """A process paused past its whole time budget (a loaded machine) still gets the descent from
    the seed: a target 11 cm from home converges, FK of the answer on the target; the budget then
    stops the restarts of an unreachable target after the first descent."""
    solver = model.solver("lm")
    clock = solver.clock
    ticks = iter(range(10**6))
    solver.clock = lambda: float(next(ticks))  # every reading is a second past the last: budget spent
    try:
        target = model.fk(model.home)
        target[:3, 3] += [0.05, 0.0, -0.10]
        res = model.ik(target, model.home, time_budget=0.02)
        far = model.fk(model.home)
        far[:3, 3] += [3.0, 0.0, 0.0]
        lost = model.ik(far, model.home, time_budget=0.02)
    finally:
        solver.clock = clock
    assert res.converged and res.restarts == 0
    np.testing.assert_allclose(model.fk(res.q)[:3, 3], target[:3, 3], atol=1e-4)
    assert not lost.converged and lost.restarts <= 1
