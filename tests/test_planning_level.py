"""Carrying a held object at the orientation it was picked up with (``robocfg.planning.level``):
the planner's path round a wall, re-solved with the hand's orientation kept, stays collision-free
and keeps the hand within the tilt limit where the raw path turned it; a path that cannot be
mended is given back unchanged; the planned pick-place carries its cube so."""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np
import pytest
from _sim_helpers import PANDA

from robocfg.checks import load_robot, load_task
from robocfg.collision import EnvShape, robot_geometry
from robocfg.config import catalog
from robocfg.kinematics.model import KinematicModel
from robocfg.planning import JointPlanner
from robocfg.planning.checker import CollisionChecker
from robocfg.planning.level import LevelSettings, level_path, turn

DOWN = np.diag([1.0, -1.0, -1.0])
GROUND = EnvShape("ground", "halfspace", (), np.eye(4), obstacle=False)
STEP = 0.02  # rad: the planner's default segment resolution


def _box(name, size, pos):
    T = np.eye(4)
    T[:3, 3] = pos
    return EnvShape(name, "box", tuple(size), T)


WALL = _box("wall", [0.16, 0.04, 0.2], [0.5, 0.0, 0.1])  # the obstacle task's wall, between the two poses below


@pytest.fixture(scope="module")
def carry():
    """The Panda holding a 5 cm box 10 cm beyond the flange, start and goal on either side of the
    wall with the hand pointing down, and the planner's raw path between them."""
    robot = load_robot(PANDA)
    kin = KinematicModel.from_robot(robot)
    held = np.eye(4)
    held[2, 3] = 0.1

    def checker_with_cube(margin=0.01):
        c = CollisionChecker(kin, robot_geometry(robot)[0], [GROUND, WALL], margin=margin)
        c.attach("cube", EnvShape("cube", "box", (0.05, 0.05, 0.05), held), kin.ee_link)
        return c

    checker = checker_with_cube()

    def ik(pos, seed):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = DOWN, pos
        res = kin.ik(T, seed_q=seed, frame="ee", time_budget=0.2)
        assert res.converged
        return res.q

    qs = ik([0.5, -0.2, 0.25], kin.home)
    qg = ik([0.5, 0.2, 0.25], qs)
    path = JointPlanner(checker, kin.lower, kin.upper).plan(qs, qg)
    assert path.method == "rrt_connect"
    return kin, checker, held[:3, 3], path.waypoints, checker_with_cube(0.005)


def _fk(kin):
    return lambda q: kin.fk(q, "ee")


def _solve(kin):
    def solve(T, seed):
        res = kin.ik(T, seed_q=seed, frame="ee", time_budget=0.2)
        return res.q if res.converged else None

    return solve


def _worst_turn(kin, path, per_segment=40) -> float:
    R_goal = kin.fk(path[-1], "ee")[:3, :3]
    return max(turn(kin.fk(a + f * (b - a), "ee")[:3, :3], R_goal)
               for a, b in itertools.pairwise(path) for f in np.linspace(0.0, 1.0, per_segment))


def _dense_valid(checker, path, step=0.005) -> bool:
    for a, b in itertools.pairwise(path):
        n = max(1, int(np.ceil(np.max(np.abs(b - a)) / step)))
        if not all(checker.is_valid(a + s * (b - a)) for s in np.linspace(0, 1, n + 1)):
            return False
    return True


def test_turn_is_the_rotation_angle():
    c, s = np.cos(0.3), np.sin(0.3)
    Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert turn(DOWN, DOWN) == pytest.approx(0.0, abs=1e-7)
    assert turn(DOWN @ Rz, DOWN) == pytest.approx(0.3)


def test_the_carry_round_the_wall_keeps_the_hand_as_it_holds_the_box(carry):
    kin, checker, pivot, raw, finer = carry
    settings = LevelSettings()
    assert _worst_turn(kin, raw) > 2 * settings.max_tilt  # the raw path turns the hand (the case at hand)
    out = level_path(raw, checker, _fk(kin), _solve(kin), STEP, pivot, settings)
    assert np.array_equal(out[0], raw[0]) and np.array_equal(out[-1], raw[-1])
    assert _worst_turn(kin, out) <= 1.5 * settings.max_tilt  # checked at 8 points a segment, here at 40
    assert all(checker.segment_valid(a, b, STEP) for a, b in itertools.pairwise(out))
    assert _dense_valid(finer, out)  # at 5 mm margin, every 0.005 rad
    # the same answer for the same path
    assert np.array_equal(out, level_path(raw, checker, _fk(kin), _solve(kin), STEP, pivot, settings))


def test_a_path_that_cannot_be_levelled_is_given_back_unchanged(carry):
    kin, checker, pivot, raw, _ = carry
    assert np.array_equal(level_path(raw, checker, _fk(kin), lambda T, q: None, STEP, pivot), raw)
    turned = raw.copy()  # a path that starts with the hand turned away from the goal's orientation
    turned[0] = raw[0] + np.array([0, 0, 0, 0, 0, 0, 0.5])
    assert np.array_equal(level_path(turned, checker, _fk(kin), _solve(kin), STEP, pivot), turned)


@pytest.mark.parametrize("episode", [0, 6])
def test_the_planned_pick_place_carries_the_cube_without_turning_the_hand(episode):
    """Seed 0 of the obstacle task: episode 0's raw transport path tilted the hand 21°; in
    episode 6 a levelled waypoint where the raw one was would take the cube through the wall's
    edge (it is raised). The transport path the planner drove keeps the hand within the limit,
    and the cube was placed."""
    from robocfg.engine import RunOptions
    from robocfg.runners.pick_place import PickPlaceRunner

    task = load_task(catalog.find("tasks", "pick_place_obstacle"))
    params = task.config.pick_place.model_copy(update={"motion": "planned"})
    task = replace(task, config=task.config.model_copy(update={"pick_place": params}))
    with PickPlaceRunner(task, RunOptions(seed=0, episodes=1)).open_session() as session:
        record = session.run(episode)
        drive = session.tools.planned
        kin = session.tools.model
    assert record.success, (record.failed_phase, record.reason)
    _pre_grasp, transport = drive.paths
    assert len(transport.waypoints) > 2  # round the wall, not a straight joint move
    assert _worst_turn(kin, transport.waypoints) <= 1.5 * LevelSettings().max_tilt
