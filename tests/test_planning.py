"""Global planner on the Panda (kinematic: pinocchio + coal + OMPL, no physics): collision checks,
held objects, RRT-Connect around a wall, shortening, timing, failures, reproducibility."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from _sim_helpers import PANDA, panda_branch_case

from robocfg.checks import load_robot
from robocfg.collision import EnvShape, robot_geometry
from robocfg.config import catalog
from robocfg.kinematics.model import KinematicModel
from robocfg.motion.limits import make_limits
from robocfg.planning import JointPlanner, PlannerSettings, PlanningFailed
from robocfg.planning.checker import CollisionChecker
from robocfg.planning.shortcut import path_length

DOWN = np.diag([1.0, -1.0, -1.0])  # TCP z pointing down


def _box(name, size, pos):
    T = np.eye(4)
    T[:3, 3] = pos
    return EnvShape(name, "box", tuple(size), T)


GROUND = EnvShape("ground", "halfspace", (), np.eye(4), obstacle=False)
WALL = _box("wall", [0.3, 0.04, 0.4], [0.55, 0.0, 0.2])  # between the two TCP positions below


@pytest.fixture(scope="module")
def panda():
    robot = load_robot(PANDA)
    return robot, KinematicModel.from_robot(robot), robot_geometry(robot)[0]


def _checker(panda, env=(), **kw):
    _, kin, links = panda
    return CollisionChecker(kin, links, [GROUND, *env], **kw)


def _ik(kin, pos, seed=None):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = DOWN, pos
    res = kin.ik(T, seed_q=kin.home if seed is None else seed, time_budget=0.2)
    assert res.converged
    return res.q


@pytest.fixture(scope="module")
def wall_query(panda):
    """Start and goal with the TCP 15 cm above the floor on either side of the wall."""
    _, kin, _ = panda
    return _ik(kin, [0.55, -0.25, 0.15]), _ik(kin, [0.55, 0.25, 0.15])


def _dense_valid(checker, path, step=0.005):
    """Every point of the polyline, at ``step`` rad, is collision-free (a finer check than the planner's)."""
    for a, b in itertools.pairwise(path):
        n = max(1, int(np.ceil(np.max(np.abs(b - a)) / step)))
        for s in np.linspace(0, 1, n + 1):
            if not checker.is_valid(a + s * (b - a)):
                return False
    return True


def test_home_is_free_and_a_box_through_the_hand_is_a_named_collision(panda):
    _, kin, _ = panda
    free = _checker(panda)
    assert free.is_valid(kin.home)
    hand = kin.fk(kin.home, "ee")[:3, 3]
    blocked = _checker(panda, [_box("crate", [0.1, 0.1, 0.1], hand)])
    assert not blocked.is_valid(kin.home)
    hits = blocked.contacts(kin.home)
    assert any(c.b == "crate" and c.a.startswith("panda_") for c in hits)
    assert blocked.clearance(kin.home) < 0


def test_margin_counts_near_misses_as_collisions(panda):
    _, kin, _ = panda
    tip = kin.fk(kin.home)[:3, 3]  # TCP between the fingertips
    fingertip_clear = _box("plate", [0.3, 0.3, 0.02], tip - [0, 0, 0.04])  # ~2–3 cm below the fingers
    d = _checker(panda, [fingertip_clear], margin=0.0).clearance(kin.home, scene_only=True)
    assert 0.0 < d < 0.05
    assert _checker(panda, [fingertip_clear], margin=0.0).is_valid(kin.home)
    assert not _checker(panda, [fingertip_clear], margin=d + 0.005).is_valid(kin.home)


def test_attached_object_collides_and_detaches(panda):
    _, kin, _ = panda
    T_ee = kin.fk(kin.home, "ee")
    below = T_ee[:3, 3] + T_ee[:3, 2] * 0.25  # 25 cm beyond the flange along its z: below the fingers
    shelf = _box("ledge", [0.2, 0.2, 0.02], below)
    c = _checker(panda, [shelf])
    assert c.is_valid(kin.home)
    held = np.eye(4)
    held[2, 3] = 0.2  # a 12 cm tall box centred 20 cm from the flange: its bottom reaches the ledge
    c.attach("cube", EnvShape("cube", "box", (0.05, 0.05, 0.12), held), kin.ee_link)
    assert c.held == ["cube"]
    assert not c.is_valid(kin.home)
    assert any(h.a == "held object 'cube'" and h.b == "ledge" for h in c.contacts(kin.home))
    c.detach("cube")
    assert c.held == [] and c.is_valid(kin.home)


def test_rrt_connect_goes_around_the_wall(panda, wall_query):
    _, kin, _ = panda
    qs, qg = wall_query
    c = _checker(panda, [WALL])
    planner = JointPlanner(c, kin.lower, kin.upper)
    assert not c.segment_valid(qs, qg, 0.02)  # the straight joint move hits the wall
    path = planner.plan(qs, qg)
    assert path.method == "rrt_connect"
    assert np.allclose(path.waypoints[0], qs) and np.allclose(path.waypoints[-1], qg)
    assert _dense_valid(_checker(panda, [WALL], margin=0.005), path.waypoints)
    assert path.length <= path.raw_length + 1e-9
    assert path.length == pytest.approx(path_length(path.waypoints))
    assert np.all(path.waypoints >= kin.lower - 1e-9) and np.all(path.waypoints <= kin.upper + 1e-9)


def test_free_space_move_is_one_straight_segment(panda, wall_query):
    _, kin, _ = panda
    qs, qg = wall_query
    path = JointPlanner(_checker(panda), kin.lower, kin.upper).plan(qs, qg)
    assert path.method == "direct" and len(path.waypoints) == 2


def test_same_query_same_path_whatever_was_planned_before(panda, wall_query):
    _, kin, _ = panda
    qs, qg = wall_query
    planner = JointPlanner(_checker(panda, [WALL]), kin.lower, kin.upper)
    first = planner.plan(qs, qg)
    planner.plan(qg, qs)  # another query in between
    again = planner.plan(qs, qg)
    assert np.array_equal(first.waypoints, again.waypoints)
    assert first.checks == again.checks


def test_timed_path_stays_collision_free_and_within_limits(panda, wall_query):
    _robot, kin, _ = panda
    qs, qg = wall_query
    c = _checker(panda, [WALL])
    planner = JointPlanner(c, kin.lower, kin.upper)
    path = planner.plan(qs, qg)
    limits = make_limits(kin.joint_names, kin.lower, kin.upper, kin.velocity_limits, np.full(kin.nq, 5.0))
    plan = planner.timed(path, limits)
    t = np.linspace(0, plan.duration, 400)
    q, dq, _ = plan.trajectory.evaluate(t)
    assert np.allclose(q[0], qs, atol=1e-6) and np.allclose(q[-1], qg, atol=1e-6)
    assert np.all(np.abs(dq) <= kin.velocity_limits * (1 + 1e-3))
    assert all(c.is_valid(x) for x in q)


def test_goal_in_collision_names_the_pair(panda, wall_query):
    _, kin, _ = panda
    qs, _ = wall_query
    q_in = _ik(kin, [0.55, 0.0, 0.3])  # the hand inside the wall
    planner = JointPlanner(_checker(panda, [WALL]), kin.lower, kin.upper)
    with pytest.raises(PlanningFailed, match=r"goal configuration is in collision \(panda_\w+ with wall"):
        planner.plan(qs, q_in)


def test_exhausted_budget_fails_with_the_budget_in_ms(panda, wall_query):
    _, kin, _ = panda
    qs, qg = wall_query
    planner = JointPlanner(_checker(panda, [WALL]), kin.lower, kin.upper, PlannerSettings(budget_ms=1.0))
    with pytest.raises(PlanningFailed, match=r"^no collision-free path found in 1 ms \(\d+ collision checks\)$"):
        planner.plan(qs, qg)


def test_a_goal_past_a_full_turn_is_brought_next_to_the_start_and_reached():
    """UR5e joints span ±2π: an IK answer one turn away (the same pose) is planned to the
    equivalent angle next to the start, and the search box stays within π of start and goal."""
    robot = load_robot(catalog.find("robots", "ur5e_robotiq_2f85"))
    kin = KinematicModel.from_robot(robot)
    planner = JointPlanner(CollisionChecker(kin, robot_geometry(robot)[0], [GROUND]), kin.lower, kin.upper)
    qs = np.array(kin.home, float)
    qg = qs + np.array([0.3, 0.0, 0.0, 0.0, 0.0, 2 * np.pi - 0.2])  # wrist 3: one turn minus 0.2 rad away
    assert kin.within_limits(qg)
    near = planner.nearest_turn(qg, qs)
    assert near[5] == pytest.approx(qs[5] - 0.2) and near[0] == pytest.approx(qg[0])
    assert np.allclose(kin.fk(near), kin.fk(qg), atol=1e-9)  # the same TCP pose
    path = planner.plan(qs, qg)
    assert np.allclose(path.waypoints[-1], near) and path.length < 1.0
    lo, hi = planner.search_box(qs, near)
    assert np.all(lo >= kin.lower) and np.all(hi <= kin.upper)
    assert hi[5] - lo[5] == pytest.approx(0.2 + 2 * np.pi)  # [min − π, max + π] for a ±2π joint


def test_goal_prefers_an_ik_answer_whose_straight_line_after_it_is_continuous(panda):
    """A top-down pre-grasp pose whose nearest IK answer (from this start) has the wrist past
    2.9 rad: going 13 cm straight down from it, a joint jumps (a branch is crossed). With the line
    given, the drive's goal is another answer of the same pose, collision-free, from which the
    line is continuous; without it, the nearest answer as before."""
    from robocfg.motion.moves import ArmMover, MoveFailed, bound_ik_by_iterations
    from robocfg.planning.drive import PlannedDrive

    _, kin, links = panda
    bound_ik_by_iterations(kin)
    checker = CollisionChecker(kin, links, [GROUND])
    drive = PlannedDrive(JointPlanner(checker, kin.lower, kin.upper), kin, kin.ee_link, [])
    mover = ArmMover(None, None, kin, None)  # type: ignore[arg-type]  # IK only: no world
    T, T_down, q0 = panda_branch_case()
    nearest = mover.solve(T, q0)
    with pytest.raises(MoveFailed, match="no continuous IK along the straight line"):
        mover.straight_waypoints(nearest, T_down)
    assert np.allclose(drive.goal(mover, T, q0), nearest)
    q = drive.goal(mover, T, q0, lines=[T_down])
    assert checker.is_valid(q) and np.allclose(kin.fk(q, "ee"), T, atol=1e-3)
    W = mover.straight_waypoints(q, T_down)
    assert np.allclose(kin.fk(W[-1], "ee"), T_down, atol=1e-3)
