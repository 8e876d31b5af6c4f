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
