"""Pick-place with ``motion: reactive``: the follow-target controller carries the cube over a wall
that a joint-space transport runs into, and the robot never touches it."""

from dataclasses import replace

import numpy as np
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


def _box_obj(path, size) -> None:
    """An OBJ mesh of a box of ``size`` (m), centred on its frame."""
    import itertools

    hx, hy, hz = (s / 2 for s in size)
    corners = list(itertools.product((-hx, hx), (-hy, hy), (-hz, hz)))
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = [f"v {x} {y} {z}" for x, y, z in corners]
    lines += [f"f {a} {b} {c}\nf {a} {c} {d}" for a, b, c, d in faces]
    path.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def mesh_wall_task(tmp_path_factory):
    """The obstacle task with its wall given as a mesh (an OBJ box of the same size and pose)."""
    import yaml

    folder = tmp_path_factory.mktemp("mesh_wall")
    _box_obj(folder / "wall.obj", [0.16, 0.04, 0.2])
    doc = yaml.safe_load(catalog.find("tasks", "pick_place_obstacle").read_text())
    wall = doc["scene"]["obstacles"][0]
    wall.update(shape="mesh", mesh="wall.obj", size=[1.0, 1.0, 1.0])
    path = folder / "pick_place_mesh_wall.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return load_task(path)


def test_the_reactive_controller_sees_a_mesh_obstacle_as_the_planner_does(mesh_wall_task):
    """A mesh obstacle is in the controller's collision model as the convex hull the planner uses
    (it was left out, with a warning that it is not avoided)."""
    from robocfg.motion.reactive.setup import MeshPoses, scene_shapes

    scene = mesh_wall_task.config.scene
    assert scene_shapes(scene)[1] == ["wall"]  # without poses: left out and named
    shapes, skipped = scene_shapes(scene, MeshPoses(mesh_wall_task.path.parent, lambda b: np.eye(4)))
    assert skipped == []
    wall = next(s for s in shapes if s.name == "wall")
    assert wall.kind == "convex" and np.allclose(np.ptp(wall.vertices, axis=0), [0.16, 0.04, 0.2])


@pytest.mark.parametrize("seed", [0, 1])
def test_reactive_transport_goes_round_a_mesh_wall(mesh_wall_task, seed):
    """The wall as a mesh: the reactive transport goes round it and never touches it (with the
    mesh left out of the controller's model the transport runs into it)."""
    episode, spy = _run(mesh_wall_task, seed)
    assert episode.success, (episode.failed_phase, episode.reason)
    assert spy.checked > 500
    assert spy.robot_hits == 0
    assert spy.cube_hits == 0
