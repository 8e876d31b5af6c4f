"""Per-robot ``variants`` in a task YAML: the entry of the robot that runs is applied, user
overrides win over it, and every other entry is checked when the file is checked as written."""

from __future__ import annotations

import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.errors import ConfigError


def _cell(tmp_path, variants):
    data = yaml.safe_load(catalog.find("tasks", "pick_place_cell").read_text())
    data["variants"] = variants
    path = tmp_path / "cell.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_the_running_robots_variant_is_applied_and_others_are_not():
    cell = catalog.find("tasks", "pick_place_cell")
    kuka, maira = load_task(cell), load_task(cell, robot_override="neura_maira7m")
    assert kuka.config.pick_place.place_position == [-1.7, 0.0, 0.0]
    assert maira.config.pick_place.place_position == [-0.556, -0.225, 0.0]
    assert maira.config.scene.objects[1].position == [-0.556, -0.225, 1.08]
    assert maira.config.scene.pedestal.radius == 0.25 and kuka.config.scene.pedestal.radius == 0.6
    assert maira.robots[0].config.name == "neura_maira7m"


def test_user_overrides_win_over_the_variant():
    task = load_task(catalog.find("tasks", "pick_place_cell"), robot_override="neura_maira7m",
                     overrides={"robots.0.robot": "neura_maira7m", "pick_place.lift_height": 0.15})
    assert task.config.pick_place.lift_height == 0.15
    assert task.config.pick_place.above_height == 0.2  # from the variant


def test_a_variant_for_an_unknown_robot_is_an_error_with_a_suggestion(tmp_path):
    with pytest.raises(ConfigError) as exc:
        load_task(_cell(tmp_path, {"abb_irb760": {"pick_place.lift_height": 0.2}}))
    text = str(exc.value)
    assert "variants.abb_irb760" in text and "did you mean 'abb_irb7600'" in text


def test_a_variant_that_breaks_the_task_is_reported_at_its_key(tmp_path):
    with pytest.raises(ConfigError) as exc:
        load_task(_cell(tmp_path, {"abb_irb7600": {"pick_place.lift_height": -1.0}}))
    text = str(exc.value)
    assert "with robot 'abb_irb7600' the task is invalid" in text
    assert "variants.abb_irb7600.pick_place.lift_height: Input should be greater than 0" in text
