"""``run pick-place-many``: several objects, each in its own region, checked before simulating
(place target, capacity, regions into fixtures and into each other), picked with clutter-filtered
grasps and placed on spots that keep them apart; failures name the object and the phase."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.checks.clutter import footprint_radius, place_spots
from robocfg.config import catalog
from robocfg.engine import RunOptions
from robocfg.errors import ConfigError
from robocfg.runners.pick_place_many import PickPlaceManyRunner


@pytest.fixture(scope="module")
def bin_to_bin():
    return load_task(catalog.find("tasks", "pick_place_bin_to_bin"))


def _variant(tmp_path, task, change) -> object:
    """The shipped task's YAML with ``change(data)`` applied, loaded from ``tmp_path``."""
    data = copy.deepcopy(yaml.safe_load(task.path.read_text()))
    data.pop("$schema", None)
    change(data)
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _problems(path) -> list:
    with pytest.raises(ConfigError) as exc:
        load_task(path)
    return exc.value.problems


def test_place_spots_keep_objects_apart_and_inside_the_bin(bin_to_bin):
    params = bin_to_bin.config.pick_place_many
    r = max(footprint_radius(o, bin_to_bin.path.parent) for o in params.objects)
    spots = place_spots(bin_to_bin.config.scene, params.place, r).points
    assert len(spots) >= len(params.objects)
    d = np.linalg.norm(spots[:, None, :2] - spots[None, :, :2], axis=2) + np.eye(len(spots))
    assert d.min() >= 2 * r + params.place.gap - 1e-9  # footprints never touch, whatever the yaw
    # inside bin_b's walls (x 0.34..0.66, y 0.04..0.48 inside) with the gap, on its 1 cm floor
    assert np.all(spots[:, 0] - r - params.place.gap >= 0.34 + 0.01 - 1e-9)
    assert np.all(spots[:, 1] + r + params.place.gap <= 0.48 - 0.01 + 1e-9)
    assert spots[:, 2] == pytest.approx(0.01)


def test_overlapping_regions_and_a_region_reaching_into_a_wall_are_refused(tmp_path, bin_to_bin):
    def change(d):
        objs = d["pick_place_many"]["objects"]
        objs[1]["position"] = [0.49, -0.38, 0.035]  # 5 cm from 'red': their regions overlap
        objs[2]["region"]["xy_range"] = [0.2, 0.0]  # 'blue' can be spawned into bin_a's x walls
    problems = _problems(_variant(tmp_path, bin_to_bin, change))
    msgs = {p.path: p.message for p in problems}
    assert "objects 'green' and 'red' can be spawned into each other" in msgs["pick_place_many.objects[1].region"]
    assert "object 'blue' can be spawned into 'bin_a/wall_" in msgs["pick_place_many.objects[2].region"]
    assert all(p.line is not None for p in problems)


def test_an_unknown_place_fixture_and_a_full_bin_are_refused(tmp_path, bin_to_bin):
    def unknown(d):
        d["pick_place_many"]["place"]["fixture"] = "bin_c"
    (p,) = _problems(_variant(tmp_path, bin_to_bin, unknown))
    assert p.path == "pick_place_many.place.fixture" and "did you mean 'bin_b'" in p.message and "known: bin_a, bin_b" in p.message

    def full(d):
        d["pick_place_many"]["place"]["gap"] = 0.1
    (p,) = _problems(_variant(tmp_path, bin_to_bin, full))
    assert p.path == "pick_place_many.place.gap" and "holds 1 of the 5 objects" in p.message


def test_an_object_out_of_reach_is_refused_before_simulating(tmp_path, bin_to_bin):
    def far(d):
        d["pick_place_many"]["objects"].append({"name": "far", "shape": "box", "size": [0.05, 0.05, 0.05],
                                               "position": [1.5, 0.0, 0.025]})
        d["pick_place_many"]["place"]["gap"] = 0.01
    task = load_task(_variant(tmp_path, bin_to_bin, far))
    with pytest.raises(ConfigError) as exc:
        PickPlaceManyRunner(task, RunOptions(seed=0)).check()
    assert any(p.path == "pick_place_many.objects[5].position" and "object 'far'" in p.message
               and "out of the arm's reach (nominal point" in p.message for p in exc.value.problems)


def test_bin_to_bin_places_all_five_without_touching_a_fixture(bin_to_bin):
    runner = PickPlaceManyRunner(bin_to_bin, RunOptions(seed=0, episodes=1))
    runner.check()
    (ep,) = runner.run().report.episodes
    assert ep.success, ep.reason
    assert ep.placed == 5 and ep.order == ["red", "green", "blue", "yellow", "purple"]
    assert ep.robot_fixture_contacts == 0, ep.first_contact
    for o in ep.objects:
        assert o.success and o.place_error < 0.02 and o.tilt_deg < 15, o
        assert 0.04 < o.final[1] < 0.48 and o.final[2] < 0.06  # inside bin_b, resting low (not on another object)
        assert o.grasp_candidates > 0 and [p.name for p in o.phases][-1] == "retract"
    finals = np.array([o.final[:2] for o in ep.objects])
    gaps = np.linalg.norm(finals[:, None] - finals[None], axis=2) + np.eye(5)
    assert gaps.min() > 0.07  # on separate spots
