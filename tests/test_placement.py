"""Spots given relative to the robot (``placement: reach``): one task file puts the object within
a desk arm's reach and within a KR 210's, scaled by each arm's measured reach."""

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.motion.placement import arm_reach, resolved_params
from robocfg.motion.reach import pick_place_reach
from robocfg.runners.pick_place import run_pick_place


@pytest.fixture(scope="module", params=["panda", "kuka_kr210"])
def task(request):
    return load_task(catalog.find("tasks", "pick_place_reach"), robot_override=request.param)


def test_spots_scale_with_the_arms_reach(task):
    reach = arm_reach(task)
    params = resolved_params(task)
    given = task.config.pick_place
    assert params.placement == "world"
    np.testing.assert_allclose(params.object.position[:2], np.asarray(given.object.position[:2]) * reach, atol=1e-9)
    np.testing.assert_allclose(params.place_position[:2], np.asarray(given.place_position[:2]) * reach, atol=1e-9)
    if task.robots[0].config.name == "panda":
        assert 0.7 < reach < 0.9  # a desk arm: 855 mm from shoulder to flange
    else:
        assert 2.3 < reach < 2.9  # the KR 210 R2700
    assert pick_place_reach(task) == []  # every spot, region corners included, is reachable


def test_kr210_runs_the_relative_task():
    task = load_task(catalog.find("tasks", "pick_place_reach"), robot_override="kuka_kr210")
    report, _ = run_pick_place(task, episodes=1, seed=0)
    e = report.episodes[0]
    assert e.success, (e.failed_phase, e.reason)
    assert np.linalg.norm(e.object_start[:2]) > 1.2  # the cube is where a KR 210 works, not at a desk


def test_auto_placement_leaves_reachable_spots_alone():
    """The default task (``placement: auto``) on the robot it was written for: spots as written,
    no note (and no reach measured)."""
    from robocfg.motion.placement import resolve_placement

    task = load_task(catalog.find("tasks", "pick_place"))
    assert task.config.pick_place.placement == "auto"
    placed = resolve_placement(task)
    assert placed.note == "" and placed.reach == []
    assert list(placed.params.object.position) == list(task.config.pick_place.object.position)
    assert list(placed.params.place_position) == list(task.config.pick_place.place_position)


def test_auto_placement_scales_the_default_task_to_a_kr210():
    """``validate``'s check and one run of the default pick-place on a KR 210: the Panda's spots,
    out of its reach, scaled about the base by the ratio of the reaches; reachable; placed."""
    from robocfg.motion.placement import resolve_placement
    from robocfg.runners.pick_place import PickPlaceRunner

    task = load_task(catalog.find("tasks", "pick_place"), robot_override="kuka_kr210")
    assert task.written_robot is not None and task.written_robot.stem == "panda"
    given = task.config.pick_place
    assert any(r.nominal for r in pick_place_reach(task, params=given.model_copy(update={"placement": "world"})))
    placed = resolve_placement(task)
    assert placed.reach == [] and PickPlaceRunner.static_problems(task) == []  # validate's check
    assert "spots scaled to kuka_kr210's reach" in placed.note
    ratio = placed.params.object.position[0] / given.object.position[0]
    assert 2.5 < ratio < 4.0  # 2.7 m against 0.8 m
    np.testing.assert_allclose(placed.params.object.position[:2], np.asarray(given.object.position[:2]) * ratio, atol=1e-9)
    np.testing.assert_allclose(placed.params.place_position[:2], np.asarray(given.place_position[:2]) * ratio, atol=1e-9)
    assert placed.params.object.position[2] == given.object.position[2]
    report, _ = run_pick_place(task, episodes=1, seed=0)
    e = report.episodes[0]
    assert e.success, (e.failed_phase, e.reason)
    assert any("spots scaled" in w for w in report.warnings)


def test_auto_placement_survives_the_trip_to_a_worker_process():
    """``--workers`` sends the task as its document with ``--robot`` already applied; the robot the
    file names travels with it, so a worker scales the spots as the parent does (it used to see
    the KR 210 as the task's own robot and left the Panda's spots out of reach)."""
    import pickle

    from robocfg.engine import TaskSource
    from robocfg.motion.placement import resolve_placement

    task = load_task(catalog.find("tasks", "pick_place"), robot_override="kuka_kr210")
    there = pickle.loads(pickle.dumps(TaskSource.of(task))).load()
    assert there.written_robot == task.written_robot
    assert resolve_placement(there).params == resolve_placement(task).params


def test_auto_placement_raises_the_work_surface_for_an_arm_that_cannot_reach_the_floor():
    """The dual-arm lift's arm bases are 0.76 m up: no scaling brings the floor spots into reach.
    ``auto`` puts them on a stand whose top is where that arm reaches well (validate's check is
    clean) and the default pick-place runs on it; the Panda, which reaches the floor, gets none."""
    from robocfg.motion.placement import STAND, resolve_placement
    from robocfg.runners.pick_place import PickPlaceRunner

    task = load_task(catalog.find("tasks", "pick_place"), robot_override="dual_arm_lift")
    given = task.config.pick_place
    assert any(r.nominal for r in pick_place_reach(task, params=given.model_copy(update={"placement": "world"})))
    placed = resolve_placement(task)
    stand = placed.stand
    assert stand is not None and stand.name == STAND and "stand" in placed.note
    top = stand.position[2] + stand.size[2]
    assert 0.4 < top < 0.77  # between the floor and the arm bases, as the note says
    assert f"top {top:.2f} m high" in placed.note
    assert placed.reach == [] and PickPlaceRunner.static_problems(task) == []
    for x, y in (placed.params.object.position[:2], placed.params.place_position[:2]):
        assert abs(x - stand.position[0]) < stand.size[0] / 2 and abs(y - stand.position[1]) < stand.size[1] / 2
    report, _ = run_pick_place(task, episodes=1, seed=0)
    e = report.episodes[0]
    assert e.success, (e.failed_phase, e.reason)
    assert abs(e.object_final[2] - (top + 0.025)) < 0.005  # the cube rests on the stand's top
    assert resolve_placement(load_task(catalog.find("tasks", "pick_place"))).stand is None


def test_the_chain_bound_never_refuses_a_reachable_pose():
    """ChainBound says "no" only where no joint values reach: every FK pose of random joint values
    (within limits) on four arms passes, and a pose 1 cm past the stretched chain does not."""
    from robocfg.checks import load_robot
    from robocfg.kinematics.chain_bound import ChainBound
    from robocfg.kinematics.model import KinematicModel

    rng = np.random.default_rng(0)
    for name in ("panda", "ur5e_robotiq_2f85", "kuka_kr210", "dual_arm_lift"):
        model = KinematicModel.from_robot(load_robot(catalog.find("robots", name)))
        bound = ChainBound.of(model)
        assert bound.origin is not None and bound.length > 0.3
        lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
        hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
        for q in rng.uniform(lo, hi, (200, model.nq)):
            assert bound.may_reach(model.fk(q, "ee"))
        T = model.fk(np.asarray(model.home, float), "ee")
        last = T[:3, 3] + T[:3, :3] @ bound.last_in_ee
        away = (last - bound.origin) / np.linalg.norm(last - bound.origin)
        T[:3, 3] += away * (bound.length + 0.01 - np.linalg.norm(last - bound.origin))
        assert not bound.may_reach(T)


def test_the_stand_is_the_same_with_and_without_the_chain_bound(monkeypatch):
    """The dual-arm lift's stand and spots are found with 75 instead of 161 failing IK calls (5.2 s →
    2.2 s CPU on the 2-core laptop): the bound only skips poses IK could not reach."""
    from robocfg.kinematics.chain_bound import ChainBound
    from robocfg.motion import placement

    task = load_task(catalog.find("tasks", "pick_place"), robot_override="dual_arm_lift")
    fast = placement._resolve(task, None)
    monkeypatch.setattr(ChainBound, "may_reach", lambda self, T: True)
    slow = placement._resolve(task, None)
    assert fast.stand is not None and fast.stand == slow.stand
    assert fast.params == slow.params and fast.note == slow.note
