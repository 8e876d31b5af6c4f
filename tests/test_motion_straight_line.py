"""Straight EE lines by adaptive subdivision checked by FK (robocfg.motion.straight_line): every
waypoint's FK is its target on the line, the path that is played stays on the line (sampled far
more densely than the check does), fewer IK solves than one every 3 cm, the old failure messages,
and a real pick-place episode's EE track, read from the world, stays on its lines."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _sim_helpers import PANDA, panda_branch_case

from robocfg.checks import load_robot
from robocfg.geometry import rotation_angle
from robocfg.kinematics.model import KinematicModel
from robocfg.motion import straight_line as sl
from robocfg.motion.moves import ArmMover, MoveFailed, bound_ik_by_iterations

DOWN = np.diag([1.0, -1.0, -1.0])  # EE z pointing down


@pytest.fixture(scope="module")
def kin():
    model = KinematicModel.from_robot(load_robot(PANDA))
    bound_ik_by_iterations(model)
    return model


def _counting_mover(kin):
    mover = ArmMover(None, None, kin, None)  # type: ignore[arg-type]  # IK only: no world
    calls = []
    ik = kin.ik

    def counted(T, seed_q, frame, time_budget, **kw):
        calls.append(np.array(T))
        return ik(T, seed_q=seed_q, frame=frame, time_budget=time_budget, **kw)

    return mover, calls, counted


def _line_error(kin, q0, T_goal, path, n=2000):
    """Largest distance (m) of the path's EE from the segment FK(q0)→T_goal, and largest angle
    (rad) to the goal's orientation past the first CARTESIAN_STEP, over n samples of s."""
    p0, p1 = kin.fk(q0, "ee")[:3, 3], T_goal[:3, 3]
    u, L = (p1 - p0) / np.linalg.norm(p1 - p0), np.linalg.norm(p1 - p0)
    worst_d = worst_a = 0.0
    for q in path(np.linspace(0.0, 1.0, n)):
        T = kin.fk(q, "ee")
        v = T[:3, 3] - p0
        a = min(max(float(v @ u), 0.0), L)
        worst_d = max(worst_d, float(np.linalg.norm(v - a * u)))
        if a > sl.CARTESIAN_STEP:
            worst_a = max(worst_a, rotation_angle(T[:3, :3], T_goal[:3, :3]))
    return worst_d, worst_a


@pytest.mark.parametrize("delta", [(0.0, 0.0, -0.12), (0.25, -0.1, 0.05), (0.0, 0.0, 0.004), (-0.05, 0.3, -0.15)])
def test_waypoints_on_the_line_and_the_played_path_within_tolerance(kin, delta, monkeypatch):
    q_start = kin.ik(np.block([[DOWN, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]]),
                     seed_q=kin.home, frame="ee").q
    T0 = kin.fk(q_start, "ee")
    T_goal = T0.copy()
    T_goal[:3, 3] += delta
    mover, calls, counted = _counting_mover(kin)
    monkeypatch.setattr(kin, "ik", counted)
    W, path = mover.straight_path(q_start, T_goal)
    monkeypatch.undo()
    p0, p1 = T0[:3, 3], T_goal[:3, 3]
    assert np.array_equal(W[0], q_start) and len(W) == len(calls) + 1
    for q in W[1:]:  # each waypoint's FK is a pose of the line with the goal's orientation
        T = kin.fk(q, "ee")
        s = float((T[:3, 3] - p0) @ (p1 - p0) / ((p1 - p0) @ (p1 - p0)))
        assert -1e-6 <= s <= 1 + 1e-6
        assert np.linalg.norm(T[:3, 3] - ((1 - s) * p0 + s * p1)) < 1e-4
        assert rotation_angle(T[:3, :3], T_goal[:3, :3]) < 1e-3
    assert np.allclose(kin.fk(W[-1], "ee"), T_goal, atol=1e-4)
    d, a = _line_error(kin, q_start, T_goal, path)
    assert d <= 1.1 * sl.POSITION_TOLERANCE and a <= 1.1 * sl.ANGLE_TOLERANCE, (d, math.degrees(a))
    L = float(np.linalg.norm(np.asarray(delta)))
    assert len(calls) < max(1, math.ceil(L / sl.CARTESIAN_STEP)) or len(calls) == 1  # fewer solves than every 3 cm


@pytest.mark.parametrize("delta", [(0.0, 0.0, -0.12), (0.25, -0.1, 0.05), (-0.05, 0.3, -0.15)])
@pytest.mark.parametrize("near", [True, False])
def test_a_line_to_the_same_goal_reuses_the_checked_waypoints_that_still_hold(kin, delta, near, monkeypatch):
    """The grasp choice checks the approach from the pre-grasp answer; the approach starts where the
    pre-grasp move converged (a few 1e-5 rad away). The mover's second line to the same goal keeps
    the first's waypoints behind the new start when they pass the same FK check (no IK solve), ends
    at the same answer of the goal, and its played path is on the new line within tolerance; from
    a start far enough away that they fail (1 cm aside), the line is cut or planned afresh, still
    within tolerance."""
    T_a = np.block([[DOWN, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]])
    q_a = kin.ik(T_a, seed_q=kin.home, frame="ee").q
    T_goal = kin.fk(q_a, "ee")
    T_goal[:3, 3] += delta
    if near:  # every joint moved by up to 5e-5 rad
        q_b = q_a + 5e-5 * np.cos(np.arange(kin.nq))
    else:
        T_b = T_a.copy()
        T_b[:3, 3] += (0.006, 0.008, 0.0)
        q_b = kin.ik(T_b, seed_q=q_a, frame="ee").q
    mover, calls, counted = _counting_mover(kin)
    monkeypatch.setattr(kin, "ik", counted)
    W_a = mover.straight_waypoints(q_a, T_goal)
    first_calls = len(calls)
    calls.clear()
    W_b, path = mover.straight_path(q_b, T_goal)
    assert np.array_equal(W_b[0], q_b)
    d, a = _line_error(kin, q_b, T_goal, path)
    assert d <= 1.1 * sl.POSITION_TOLERANCE and a <= 1.1 * sl.ANGLE_TOLERANCE, (d, math.degrees(a))
    assert np.allclose(kin.fk(W_b[-1], "ee"), T_goal, atol=1e-4)
    monkeypatch.undo()
    fresh, fresh_calls, counted = _counting_mover(kin)  # nothing remembered: planned from q_b alone
    monkeypatch.setattr(kin, "ik", counted)
    W_fresh = fresh.straight_waypoints(q_b, T_goal)
    if near:  # where the pre-grasp move converges: the first line's waypoints, no solve
        assert len(calls) == 0 < first_calls
        assert W_b[1:].tobytes() == W_a[1:].tobytes()
        assert np.abs(W_b - W_fresh).max() < 1e-3  # and close to a fresh plan's
    else:  # they fail the check: a fresh plan, solve for solve
        assert len(calls) == len(fresh_calls) > 0
        assert W_b.tobytes() == W_fresh.tobytes()


def test_a_lines_cuts_are_seeded_as_a_continuation(kin, monkeypatch):
    """Each inner cut of the first guess is seeded between the previous cut's answer (the start's
    for the first) and the end's: on 4-piece lines those cuts take fewer LM iterations in all than
    the same targets seeded between the start and the end, and the line stays within tolerance."""
    q_start = kin.ik(np.block([[DOWN, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]]),
                     seed_q=kin.home, frame="ee").q
    asked, ik = [], kin.ik

    def logged(T, seed_q, frame, time_budget, **kw):
        res = ik(T, seed_q=seed_q, frame=frame, time_budget=time_budget, **kw)
        asked.append((np.array(T), res))
        return res

    ours = theirs = 0
    for delta in [(0.0, 0.0, -0.16), (0.12, -0.06, -0.08), (-0.05, 0.15, 0.02)]:
        T_goal = np.block([[DOWN, (kin.fk(q_start, "ee")[:3, 3] + delta)[:, None]], [np.zeros((1, 3)), 1.0]])
        mover, _, _ = _counting_mover(kin)
        asked.clear()
        monkeypatch.setattr(kin, "ik", logged)
        _, path = mover.straight_path(q_start, T_goal)
        monkeypatch.undo()
        n = math.ceil(float(np.linalg.norm(delta)) / sl.FIRST_PIECE - 1e-9)
        assert n == 4 and len(asked) >= n  # the end, then the 3 cuts in order
        q_end = asked[0][1].q
        for k, (T, res) in enumerate(asked[1:n], start=1):
            ours += res.iterations
            theirs += kin.ik(T, seed_q=q_start + k / n * (q_end - q_start), frame="ee", time_budget=1.0).iterations
        d, a = _line_error(kin, q_start, T_goal, path)
        assert d <= 1.1 * sl.POSITION_TOLERANCE and a <= 1.1 * sl.ANGLE_TOLERANCE
    assert ours < theirs


def test_a_line_that_crosses_a_branch_is_refused_and_an_unreachable_one_named():
    """The Panda's branch case (_sim_helpers.panda_branch_case): 13 cm straight down from this answer a
    joint would jump; and a line running out of the arm's reach names where."""
    model = KinematicModel.from_robot(load_robot(PANDA))
    bound_ik_by_iterations(model)
    mover = ArmMover(None, None, model, None)  # type: ignore[arg-type]
    T, T_down, q0 = panda_branch_case()
    nearest = mover.solve(T, q0)
    with pytest.raises(MoveFailed, match=r"no continuous IK along the straight line \(a joint jumps"):
        mover.straight_waypoints(nearest, T_down)
    T_far = T.copy()
    T_far[:3, 3] = [1.6, -0.3, 0.25]
    with pytest.raises(MoveFailed, match=r"unreachable at \d+% of the straight line"):
        mover.straight_waypoints(nearest, T_far)


def test_a_pick_place_episodes_ee_stays_on_its_lines_in_the_world(monkeypatch):
    """Played in PyBullet (Panda pick-place, seed 0, episode 0): during every straight move's
    playback the EE (read from the world every physics step) stays within 0.15 mm of its line
    and within 0.02° of the goal's orientation past the first 3 cm (3 cm spline waypoints gave
    0.111 mm / 0.002°, this 0.111 mm / 0.004°; a 0.2 mm check tolerance gave 0.206 mm)."""
    import robocfg
    from robocfg.engine import RunOptions, open_session
    from robocfg.motion import moves

    tracks = []
    play, move = moves.ArmMover.play, moves.ArmMover.move

    def spy_move(self, T_goal, straight, *a, **k):
        self._spied = (straight, self.arm.ee_pose(), np.array(T_goal))
        return move(self, T_goal, straight, *a, **k)

    def spy_play(self, traj):
        straight, T0, T_goal = self._spied
        if not straight:
            return play(self, traj)
        pts, inner = [], self.on_step

        def after():
            pts.append(self.arm.ee_pose())
            if inner is not None:
                inner()

        self.on_step = after
        try:
            play(self, traj)
        finally:
            self.on_step = inner
        tracks.append((T0, T_goal, pts))

    monkeypatch.setattr(moves.ArmMover, "move", spy_move)
    monkeypatch.setattr(moves.ArmMover, "play", spy_play)
    with open_session(robocfg.load_task("pick_place"), RunOptions(seed=0)) as session:
        assert session.run(0).success
    assert len(tracks) == 4  # approach, lift, lower, retreat
    for T0, T_goal, pts in tracks:
        p0, p1 = T0[:3, 3], T_goal[:3, 3]
        L = float(np.linalg.norm(p1 - p0))
        u = (p1 - p0) / L
        assert L > 0.1 and len(pts) > 50
        for T in pts:
            v = T[:3, 3] - p0
            a = min(max(float(v @ u), 0.0), L)
            assert np.linalg.norm(v - a * u) < 0.15e-3
            if a > sl.CARTESIAN_STEP:
                assert rotation_angle(T[:3, :3], T_goal[:3, :3]) < math.radians(0.02)


def test_linspace_in_floats_is_numpys():
    rng = np.random.default_rng(8)
    for _ in range(500):
        a, num = float(rng.uniform(0.0, 0.99)), int(rng.integers(2, 40))
        assert sl._linspace(a, 1.0, num) == np.linspace(a, 1.0, num).tolist()
    assert sl._linspace(0.0, 1.0, 2) == [0.0, 1.0]


@pytest.mark.parametrize("delta", [(0.0, 0.0, -0.12), (0.25, -0.1, 0.05), (0.0, 0.0, 0.004), (-0.05, 0.3, -0.15)])
@pytest.mark.parametrize("turn", [0.0, 0.03])
def test_straight_end_is_the_lines_last_waypoint_with_fewer_solves(kin, delta, turn, monkeypatch):
    """What a joint-space move compares with its direct answer: the end the line's first guess
    solves (from the point 3 cm along when the start is turned from the goal, rad), the same bits
    as the checked line's last waypoint, without the inner cuts' solves."""
    from robocfg.geometry.rotation import axis_angle_matrix

    R = axis_angle_matrix([0.0, 0.0, 1.0], turn) @ DOWN
    q_start = kin.ik(np.block([[R, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]]),
                     seed_q=kin.home, frame="ee").q
    T_goal = np.block([[DOWN, (kin.fk(q_start, "ee")[:3, 3] + delta)[:, None]], [np.zeros((1, 3)), 1.0]])
    mover, calls, counted = _counting_mover(kin)
    monkeypatch.setattr(kin, "ik", counted)
    W = mover.straight_waypoints(q_start, T_goal)
    line_calls = len(calls)
    calls.clear()
    q_end = mover.straight_end(q_start, T_goal)
    assert q_end.tobytes() == W[-1].tobytes()
    assert len(calls) == (2 if turn and np.linalg.norm(delta) > sl.CARTESIAN_STEP else 1)
    assert len(calls) <= line_calls


@pytest.mark.parametrize("turn", [0.0, 0.03])
def test_straight_end_after_the_direct_answer_asks_nothing_new(kin, turn, monkeypatch):
    """A joint-space move asks the goal from q0 (``ArmMover.solve``), then where a line would end:
    without a turn at the start, the line's one solve is that same question, answered from the
    mover's remembered answers (the same bits, no solve); with a turn, the point 3 cm along and the
    end from it are new questions."""
    from robocfg.geometry.rotation import axis_angle_matrix

    R = axis_angle_matrix([0.0, 0.0, 1.0], turn) @ DOWN
    q_start = kin.ik(np.block([[R, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]]),
                     seed_q=kin.home, frame="ee").q
    T_goal = np.block([[DOWN, (kin.fk(q_start, "ee")[:3, 3] + (0.25, -0.1, 0.05))[:, None]], [np.zeros((1, 3)), 1.0]])
    mover, calls, counted = _counting_mover(kin)
    monkeypatch.setattr(kin, "ik", counted)
    q_direct = mover.solve(T_goal, q_start)
    assert len(calls) == 1
    calls.clear()
    q_end = mover.straight_end(q_start, T_goal)
    assert len(calls) == (2 if turn else 0)
    if not turn:
        assert q_end.tobytes() == q_direct.tobytes()
    fresh, _, _ = _counting_mover(kin)  # nothing remembered: the same answer from the solver
    assert fresh.straight_end(q_start, T_goal).tobytes() == q_end.tobytes()


def test_straight_end_fails_where_the_lines_first_points_fail():
    """Unreachable ends are named as the line names them; where the checked line breaks further
    on (the branch case), the end is still an answer of the goal (a joint-space goal needs no
    line between)."""
    model = KinematicModel.from_robot(load_robot(PANDA))
    bound_ik_by_iterations(model)
    mover = ArmMover(None, None, model, None)  # type: ignore[arg-type]
    T, T_down, q0 = panda_branch_case()
    nearest = mover.solve(T, q0)
    assert np.allclose(model.fk(mover.straight_end(nearest, T_down), "ee"), T_down, atol=1e-4)
    T_far = T.copy()
    T_far[:3, 3] = [1.6, -0.3, 0.25]
    with pytest.raises(MoveFailed, match=r"unreachable at 100% of the straight line"):
        mover.straight_end(nearest, T_far)


@pytest.mark.parametrize("start", ["on the line at 30 %", "on the line at 60 %", "same pose, other joints",
                                   "pushed 2 cm"])
def test_a_remembered_line_from_a_very_different_start_stays_on_the_line(kin, start, monkeypatch):
    """A second line to a goal the mover has planned a line to, from a start the first line did not
    begin at (partway along it, the same EE pose with other joints, the arm pushed aside): either
    the first line's waypoints are kept and the played path stays on the new line within
    tolerance and never runs back along it, or the line is the fresh plan, bit for bit."""
    T_a = np.block([[DOWN, np.array([[0.45], [0.05], [0.35]])], [np.zeros((1, 3)), 1.0]])
    q_a = kin.ik(T_a, seed_q=kin.home, frame="ee").q
    T_goal = kin.fk(q_a, "ee")
    T_goal[:3, 3] += (0.0, 0.0, -0.12)
    mover, calls, counted = _counting_mover(kin)
    _, path_a = mover.straight_path(q_a, T_goal)
    if start.startswith("on the line"):
        q_b = path_a(np.array([0.3 if "30" in start else 0.6]))[0]
    elif start == "same pose, other joints":
        q_b = kin.ik(T_a, seed_q=q_a + np.random.default_rng(1).normal(0.0, 0.6, kin.nq), frame="ee").q
        assert np.abs(q_b - q_a).max() > 0.1
    else:
        q_b = kin.ik(T_a @ np.block([[np.eye(3), np.array([[0.02], [0.0], [0.01]])], [np.zeros((1, 3)), 1.0]]),
                     seed_q=q_a, frame="ee").q
    monkeypatch.setattr(kin, "ik", counted)
    W_b, path_b = mover.straight_path(q_b, T_goal)
    monkeypatch.undo()
    d, a = _line_error(kin, q_b, T_goal, path_b)
    assert d <= 1.1 * sl.POSITION_TOLERANCE and a <= 1.1 * sl.ANGLE_TOLERANCE, (d, math.degrees(a))
    assert np.allclose(kin.fk(W_b[-1], "ee"), T_goal, atol=1e-4)
    p0, p1 = kin.fk(q_b, "ee")[:3, 3], T_goal[:3, 3]
    along = [float((kin.fk(q, "ee")[:3, 3] - p0) @ (p1 - p0)) / float(np.linalg.norm(p1 - p0))
             for q in path_b(np.linspace(0.0, 1.0, 400))]
    assert max(np.maximum.accumulate(along) - along) < 1e-3  # no running back along the line
    if calls:  # planned afresh: the plan from q_b alone
        W_fresh = ArmMover(None, None, kin, None).straight_waypoints(q_b, T_goal)  # type: ignore[arg-type]
        assert W_b.tobytes() == W_fresh.tobytes()
