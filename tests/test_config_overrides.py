"""Dotted-key overrides: set values in a task document, validated like the file itself."""

import pytest

from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.config.overrides import apply_overrides, parse_key
from robocfg.errors import ConfigError


@pytest.fixture(scope="module")
def task():
    return load_task(catalog.find("tasks", "pick_place"))


def test_parse_key_accepts_dots_and_brackets():
    assert parse_key("robots.0.position") == ("robots", 0, "position")
    assert parse_key("robots[0].position") == ("robots", 0, "position")


def test_override_changes_the_copy_only(task):
    derived = task.with_overrides({"pick_place.lift_height": 0.2, "robots.0.position": [0.1, 0.0, 0.0]})
    assert derived.config.pick_place.lift_height == 0.2
    assert derived.config.robots[0].position == [0.1, 0.0, 0.0]
    assert task.config.pick_place.lift_height == 0.12
    assert task.doc.data["pick_place"]["lift_height"] == 0.12


def test_override_creates_missing_blocks_with_defaults(task):
    derived = task.with_overrides({"pick_place.timeouts.grasp": 3.0})
    assert derived.config.pick_place.timeouts.grasp == 3.0


def test_unknown_key_is_named_with_a_suggestion(task):
    with pytest.raises(ConfigError) as exc:
        task.with_overrides({"pick_place.lift_hight": 0.2})
    (prob,) = exc.value.problems
    assert prob.file == "override" and prob.path == "pick_place.lift_hight"
    assert "did you mean 'lift_height'" in prob.message


def test_bad_value_is_blamed_on_the_override_not_the_file(task):
    with pytest.raises(ConfigError) as exc:
        task.with_overrides({"pick_place.lift_height": "high"})
    assert [p.path for p in exc.value.problems] == ["pick_place.lift_height"]
    assert exc.value.problems[0].line is None


def test_unknown_robot_in_override_suggests_a_name(task):
    with pytest.raises(ConfigError, match="did you mean 'panda'"):
        task.with_overrides({"robots.0.robot": "pnda"})


def test_index_out_of_range_names_the_key(task):
    with pytest.raises(ConfigError) as exc:
        apply_overrides(task.doc, {"robots.3.robot": "panda"})
    assert exc.value.problems[0].path == "robots.3.robot"
    assert "no item 3" in exc.value.problems[0].message


def test_other_problems_keep_their_file_line(task):
    derived = apply_overrides(task.doc, {"pick_place.lift_height": 0.3})
    assert derived.marks[("pick_place", "above_height")] == task.doc.marks[("pick_place", "above_height")]
    assert ("pick_place", "lift_height") not in derived.marks
