"""robocfg.config.load: safe YAML with marks, duplicate keys, pydantic errors → FILE:LINE:COL."""

from __future__ import annotations

from pathlib import Path

import pytest

from robocfg.config.load import detect_kind, format_loc, load_yaml, parse_yaml
from robocfg.config.robot import RobotConfig
from robocfg.config.task import TaskConfig
from robocfg.config.validation import validate_document
from robocfg.errors import ConfigError

ROOT = Path(__file__).resolve().parent.parent
F = Path("f.yaml")


def problems(text: str, model=None) -> list:
    with pytest.raises(ConfigError) as exc:
        doc = parse_yaml(text, F)
        if model is not None:
            validate_document(doc, model)
    return exc.value.problems


def test_marks_are_one_based_key_and_item_positions():
    doc = parse_yaml("a: 1\nb:\n  c: [10, 20]\n  d:\n    - x\n    - y\n", F)
    assert doc.data == {"a": 1, "b": {"c": [10, 20], "d": ["x", "y"]}}
    assert doc.marks[("a",)] == (1, 1)
    assert doc.marks[("b", "c")] == (3, 3)
    assert doc.marks[("b", "c", 1)] == (3, 11)
    assert doc.marks[("b", "d", 1)] == (6, 7)
    assert doc.mark(("b", "d", 1, "missing", 3)) == (6, 7)  # deepest existing prefix


def test_duplicate_key_reports_second_line_and_first():
    [p] = problems("a: 1\nb:\n  c: 1\n  c: 2\n")
    assert (p.line, p.col, p.path) == (4, 3, "b.c")
    assert "duplicate key 'c'" in p.message and "line 3" in p.message


def test_duplicate_key_in_flow_mapping():
    [p] = problems("a: {x: 1, y: 2, x: 3}\n")
    assert (p.line, p.path) == (1, "a.x") and "duplicate" in p.message


@pytest.mark.parametrize(("text", "line", "snippet"), [
    ("a: [1, 2\nb: 3\n", 2, "YAML syntax error"),
    ("a: 1\n\tb: 2\n", 2, "YAML syntax error"),
    ("a: 1\n---\nb: 2\n", 2, "another document"),
    ("a: *nope\n", 1, "alias"),
    ("a: !!python/object/apply:os.system [ls]\n", 1, "not supported"),
    ("a: !!python/name:os.system\n", 1, "constructor"),
    ("a: !!set {x, y}\n", 1, "not supported"),
    ("", 1, "empty"),
    ("# only a comment\n", 1, "empty"),
    ("- 1\n- 2\n", 1, "got a list"),
    ("42\n", 1, "got a int"),
    ("a: &x [*x]\n", 1, "recursive alias"),
    ("? [1, 2]\n: 3\n", 1, "plain scalars"),
    ("a: " + "[" * 150 + "]" * 150 + "\n", 1, "levels deep"),
])
def test_bad_yaml_is_a_located_config_error(text, line, snippet):
    [p] = problems(text)
    assert p.line == line and snippet in p.message and p.file == "f.yaml"


def test_alias_bomb_is_refused_quickly():
    lines = ["a: &a [1, 2, 3, 4, 5, 6, 7, 8, 9]"]
    for prev, name in zip("abcdefgh", "bcdefghi", strict=True):
        lines.append(f"{name}: &{name} [" + ", ".join([f"*{prev}"] * 9) + "]")
    [p] = problems("\n".join(lines) + "\n")
    assert "too large" in p.message


def test_merge_keys_are_supported_and_explicit_keys_win():
    doc = parse_yaml("base: &b {x: 1, y: 2}\nc:\n  y: 3\n  <<: *b\n", F)
    assert doc.data["c"] == {"y": 3, "x": 1}
    assert doc.marks[("c", "y")] == (3, 3)


def test_load_yaml_file_errors(tmp_path):
    with pytest.raises(ConfigError) as exc:
        load_yaml(tmp_path / "nope.yaml")
    assert "not found" in exc.value.problems[0].message
    f = tmp_path / "latin1.yaml"
    f.write_bytes(b"a: 1\nb: caf\xe9\n")
    with pytest.raises(ConfigError) as exc:
        load_yaml(f)
    p = exc.value.problems[0]
    assert (p.line, p.col) == (2, 7) and "UTF-8" in p.message


def test_format_loc():
    assert format_loc(("arms", 0, "gripper", "open", 1)) == "arms[0].gripper.open[1]"
    assert format_loc(()) == ""


def _panda_text() -> str:
    return (ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text()


def test_pydantic_error_points_at_the_value_line():
    text = _panda_text().replace("tcp_offset: 0.1034", "tcp_offset: -1")
    [p] = problems(text, RobotConfig)
    assert p.path == "arms[0].tcp_offset"
    assert text.splitlines()[p.line - 1].strip() == "tcp_offset: -1"
    assert p.format().startswith(f"f.yaml:{p.line}:{p.col}: arms[0].tcp_offset: ")


def test_unknown_key_gets_a_suggestion_at_its_line():
    text = _panda_text().replace("ee_link:", "ee_lnk:")
    probs = problems(text, RobotConfig)
    unknown = next(p for p in probs if "unknown key" in p.message)
    assert unknown.path == "arms[0].ee_lnk" and "did you mean 'ee_link'?" in unknown.message
    assert text.splitlines()[unknown.line - 1].strip().startswith("ee_lnk:")
    missing = next(p for p in probs if p.path == "arms[0].ee_link")
    assert "required" in missing.message


def test_union_tag_does_not_leak_into_the_path():
    """Errors inside a tagged union member (gripper type: parallel; task: pick_place) follow the data."""
    text = _panda_text().replace("min_width: 0.0", "min_width: 0.5")
    [p] = problems(text, RobotConfig)
    assert p.path == "arms[0].gripper.min_width"
    task = (ROOT / "tests" / "data" / "task_pick_place.yaml").read_text().replace("mass: 0.1", "mass: 0.0")
    [p] = problems(task, TaskConfig)
    assert p.path == "pick_place.object.mass"
    assert task.splitlines()[p.line - 1].strip() == "mass: 0.0"


def test_unknown_discriminator_value_suggests():
    [p] = problems("schema_version: 1\ntask: pick_plac\nrobots: [{robot: panda}]\n", TaskConfig)
    assert p.path == "task" and p.line == 2 and "did you mean 'pick_place'?" in p.message


def test_block_of_another_task_kind_is_explained():
    [p] = problems("schema_version: 1\ntask: gripper\nrobots: [{robot: panda}]\ngrasp: {}\n", TaskConfig)
    assert p.path == "grasp" and p.line == 4 and "only valid with task: grasp" in p.message


def test_bare_quaternion_points_at_its_key():
    text = "schema_version: 1\ntask: gripper\nrobots:\n  - robot: panda\n    orientation: [0, 0, 0, 1]\n"
    [p] = problems(text, TaskConfig)
    assert (p.path, p.line) == ("robots[0].orientation", 5) and "quat_xyzw" in p.message


def test_detect_kind():
    assert detect_kind(parse_yaml("task: gripper\n", F)) == "task"
    assert detect_kind(parse_yaml("urdf: x.urdf\n", F)) == "robot"
    with pytest.raises(ConfigError, match="cannot tell"):
        detect_kind(parse_yaml("name: x\n", F))
