"""Scene fixtures (bins, shelves, blocks): their parts, the checks before simulating, the world
that spawns them, the planner that avoids them, and the bin-to-bin pick-place task."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from _sim_helpers import ContactSpy, run_spied

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.config.scene import Scene
from robocfg.errors import ConfigError
from robocfg.motion.reactive.setup import scene_shapes

BIN = {"type": "bin", "name": "bin_a", "size": [0.3, 0.4, 0.08], "wall": 0.01, "position": [0.45, -0.25, 0.0]}


def _scene(*fixtures, **kw) -> Scene:
    return Scene.model_validate({"fixtures": list(fixtures), **kw}, strict=False)


def test_bin_parts_are_a_floor_and_four_walls_turned_with_the_bin():
    parts = {p.name: p for p in _scene({**BIN, "euler_deg": [0, 0, 90]}).fixture_parts()}
    assert sorted(parts) == ["bin_a/floor", "bin_a/wall_+x", "bin_a/wall_+y", "bin_a/wall_-x", "bin_a/wall_-y"]
    assert parts["bin_a/floor"].position == pytest.approx([0.45, -0.25, 0.005])
    # turned 90° about z: the bin's +x wall (0.145 m out along its x) now lies along world +y
    assert parts["bin_a/wall_+x"].position == pytest.approx([0.45, -0.25 + 0.145, 0.04])
    assert all(p.mass == 0.0 and p.shape == "box" for p in parts.values())


def test_shelf_has_a_board_per_level_and_rejects_a_level_outside_it():
    shelf = {"type": "shelf", "name": "rack", "size": [0.3, 0.8, 0.9], "levels": [0.3, 0.6], "position": [0.7, 0, 0]}
    parts = {p.name: p for p in _scene(shelf).fixture_parts()}
    assert {"rack/back", "rack/bottom", "rack/top", "rack/level_1", "rack/level_2"} <= set(parts)
    assert parts["rack/level_1"].position[2] + parts["rack/level_1"].size[2] / 2 == pytest.approx(0.3)
    with pytest.raises(ValueError, match=r"shelf level 1\.2 m is outside the shelf"):
        _scene({**shelf, "levels": [1.2]})


def _task_file(tmp_path, fixtures, obj_position, obstacles=()):
    data = {
        "schema_version": 1, "task": "pick_place", "robots": [{"robot": "panda"}],
        "scene": {"ground": True, "fixtures": fixtures, "obstacles": list(obstacles)},
        "pick_place": {"object": {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "position": obj_position},
                       "place_position": [0.45, 0.25, 0.0]},
    }
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_an_object_spawned_inside_a_bin_wall_is_refused_with_its_location(tmp_path):
    path = _task_file(tmp_path, [BIN], [0.45, -0.06, 0.035])  # straddles the +y wall (y = -0.06 ± 0.005)
    with pytest.raises(ConfigError) as exc:
        load_task(path)
    (problem,) = exc.value.problems
    assert problem.line is not None and problem.path == "pick_place.object.position"
    assert "object 'cube' is inside fixture part 'bin_a/wall_+y'" in problem.message


def test_an_object_resting_in_the_bin_is_accepted(tmp_path):
    load_task(_task_file(tmp_path, [BIN], [0.45, -0.25, 0.035]))  # on the 1 cm floor: touching, not inside


def test_overlapping_fixtures_and_clashing_names_are_refused(tmp_path):
    other = {**BIN, "name": "bin_b", "position": [0.45, -0.05, 0.0]}  # half inside bin_a
    clash = {**BIN, "name": "wall", "position": [0.45, 0.4, 0.0]}
    path = _task_file(tmp_path, [BIN, other, clash], [0.45, -0.25, 0.035],
                      obstacles=[{"name": "wall", "shape": "box", "size": [0.1, 0.1, 0.1], "position": [-0.5, 0, 0.05]}])
    with pytest.raises(ConfigError) as exc:
        load_task(path)
    messages = [p.message for p in exc.value.problems]
    assert any("fixture name 'wall' is already used at scene.obstacles.0" in m for m in messages)
    assert any(m.startswith("fixture part 'bin_b/") and "overlaps fixture part 'bin_a/" in m for m in messages)


@pytest.fixture(scope="module")
def bins():
    return load_task(catalog.find("tasks", "pick_place_bins"))


def test_the_planner_and_the_controller_see_every_part(bins):
    shapes, skipped = scene_shapes(bins.config.scene)
    names = {s.name for s in shapes if s.obstacle}
    assert {"bin_a/floor", "bin_a/wall_+y", "bin_b/wall_-y"} <= names and skipped == []


class _BinSpy(ContactSpy):
    """Counts steps where a moving robot link touches any bin part (penetration)."""

    def maybe_capture(self):
        import pybullet as p

        w, c = self.world, self.world.client
        parts = [bid for name, bid in w.bodies.items() if name.startswith("bin_")]
        hits = [k for b in parts for k in p.getContactPoints(w.robot.body_id, b, physicsClientId=c) if k[8] < 0 and k[3] != -1]
        self.robot_hits += bool(hits)
        self.checked += 1


def test_bin_to_bin_places_the_cube_without_touching_a_bin(bins):
    report, spy = run_spied(bins, lambda world: _BinSpy(world, obstacle="bin_a/floor"), seed=2)
    episode = report.episodes[0]
    assert episode.success, (episode.failed_phase, episode.reason)
    assert episode.object_final[1] > 0.05 + 0.01  # inside bin_b (its -y wall is at y = 0.05)
    assert episode.object_final[2] == pytest.approx(0.01 + 0.025, abs=0.005)  # on bin_b's floor
    assert spy.checked > 500 and spy.robot_hits == 0
    assert np.isfinite(episode.place_error)
