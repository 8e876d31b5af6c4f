"""Pick-place with ``motion: reactive``: the follow-target controller carries the cube over a wall
that a joint-space transport runs into, and the robot never touches it."""

from dataclasses import replace

import pytest
from _sim_helpers import ContactSpy

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.config.commands import PickPlaceParams
from robocfg.runners.pick_place import run_pick_place


@pytest.fixture(scope="module")
def task():
    return load_task(catalog.find("tasks", "pick_place_obstacle"))


def _run(task, seed: int):
    spies = []

    def factory(world):
        spies.append(ContactSpy(world))
        return spies[-1]

    report, _ = run_pick_place(task, episodes=1, seed=seed, record=factory)
    return report.episodes[0], spies[0]


def test_the_task_asks_for_the_reactive_mode_and_the_default_is_trajectory(task):
    assert task.config.pick_place.motion == "reactive"
    assert PickPlaceParams.model_fields["motion"].default == "trajectory"
    assert [o.name for o in task.config.scene.obstacles] == ["wall"]


@pytest.mark.parametrize("seed", [0, 1])
def test_reactive_transport_goes_round_the_wall(task, seed):
    episode, spy = _run(task, seed)
    assert episode.success, (episode.failed_phase, episode.reason)
    assert [p.name for p in episode.phases][:5] == ["pre_grasp", "approach", "grasp", "lift", "transport"]
    assert spy.checked > 500
    assert spy.robot_hits == 0
    assert spy.cube_hits == 0  # the held cube is modelled by the controller too


def test_a_joint_space_transport_hits_the_wall(task):
    """The wall is really in the way: the same scene with ``motion: trajectory`` runs into it."""
    params = task.config.pick_place.model_copy(update={"motion": "trajectory",
                                                       "timeouts": task.config.pick_place.timeouts.model_copy(update={"transport": 2.0})})
    trajectory_task = replace(task, config=task.config.model_copy(update={"pick_place": params}))
    episode, spy = _run(trajectory_task, 0)
    assert not episode.success and episode.failed_phase == "transport"
    assert spy.robot_hits > 0
