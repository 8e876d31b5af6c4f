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
