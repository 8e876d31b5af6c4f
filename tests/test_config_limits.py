"""Text pre-scan (size, nesting), strict numbers, and the IK backend names table."""

from __future__ import annotations

from pathlib import Path

import pytest

from robocfg.config.load import parse_yaml
from robocfg.config.prescan import MAX_BYTES, MAX_DEPTH, check_depth, check_size
from robocfg.config.robot import IK_BACKENDS
from robocfg.errors import ConfigError
from robocfg.kinematics.ik.registry import known_backends

ROOT = Path(__file__).resolve().parent.parent


def test_ik_backend_table_matches_the_registry():
    assert sorted(IK_BACKENDS) == known_backends()


def test_no_shipped_yaml_trips_the_depth_prescan():
    files = [p for p in ROOT.rglob("*.y*ml") if ".git" not in p.parts and p.suffix in (".yaml", ".yml")]
    assert len(files) > 20
    for p in files:
        assert check_depth(p.read_text(errors="replace")) is None, p


@pytest.mark.parametrize(("text", "line"), [
    ("a: " + "[" * (MAX_DEPTH + 5) + "]" * (MAX_DEPTH + 5), 1),
    ("a: 1\nb:\n" + "  - " + "- " * (MAX_DEPTH + 5) + "x\n", 3),
    ("a:\n  b: {c: " * 1 + "{d: " * (MAX_DEPTH + 5) + "1" + "}" * (MAX_DEPTH + 6), 2),
])
def test_deep_nesting_is_refused_at_its_line(text, line):
    hit = check_depth(text)
    assert hit is not None and hit.line == line and "nested more than" in hit.message
    with pytest.raises(ConfigError) as exc:
        parse_yaml(text, Path("x.yaml"))
    assert exc.value.problems[0].line == line


@pytest.mark.parametrize("text", [
    "a: '[[[[[[[['\n" * 3 + "b: \"{{{{\\\"{{{{\"\n",
    "a: |\n  " + "[" * 300 + "\n  - - - - -\nb: 1\n",
    "a: x[[[[ # [[[[[[\n" * 50,
    "a: [1, [2, [3]], {b: [4]}]\n",
])
def test_brackets_in_text_are_not_nesting(text):
    assert check_depth(text, limit=5) is None


def test_size_limit():
    assert check_size(MAX_BYTES) is None
    hit = check_size(MAX_BYTES + 1)
    assert hit is not None and hit.line == 1 and "KiB" in hit.message


def test_exponent_floats_and_no_booleans_as_numbers():
    from robocfg.config.commands import GripperParams
    from robocfg.config.validation import validate_document

    doc = parse_yaml("rate: 5e-1\nhold_time: 2E0\n", Path("g.yaml"))
    assert validate_document(doc, GripperParams).rate == 0.5
    for bad in ("rate: true", "rate: '0.5'", "cycles: true", "cycles: 1.5"):
        with pytest.raises(ConfigError) as exc:
            validate_document(parse_yaml(bad, Path("g.yaml")), GripperParams)
        [p] = exc.value.problems
        assert (p.line, p.path) == (1, bad.split(":")[0])
