"""Fuzz the loader and the checks: whatever the YAML, the only exception is ConfigError.

Two sources of documents: random nested data (keys drawn partly from real field names) and
near-valid documents made by mutating the shipped Panda robot and a valid pick-place task.
"""

from __future__ import annotations

import copy
import os
import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robocfg.checks import load_robot, load_task
from robocfg.config.load import detect_kind, load_yaml
from robocfg.errors import ConfigError

ROOT = Path(__file__).resolve().parent.parent
PANDA = yaml.safe_load((ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text())
PANDA["urdf"] = "pybullet_data://franka_panda/panda.urdf"
TASK = yaml.safe_load((ROOT / "tests" / "data" / "task_pick_place.yaml").read_text())
TASK["robots"][0]["robot_config_file"] = str(ROOT / "robocfg" / "data" / "robots" / "panda.yaml")

FIELD_NAMES = sorted({
    "schema_version", "name", "urdf", "arms", "joints", "joint_indices", "ee_link", "base_link",
    "tcp_offset", "ee_axis", "R_ee_graspnet", "home", "home_std", "gripper", "type", "open",
    "closed", "max_width", "min_width", "finger_links", "task", "robots", "robot", "scene",
    "objects", "sim", "position", "euler_deg", "quat_xyzw", "orientation", "size", "shape",
    "pick_place", "object", "place_position", "drives", "physics", "<<",
})
_TMP = tempfile.TemporaryDirectory(prefix="robocfg-fuzz-")
# ROBOCFG_FUZZ_SCALE=20 runs a 20x longer campaign (done once before committing; nothing found).
SCALE = int(os.environ.get("ROBOCFG_FUZZ_SCALE", "1"))
SETTINGS = settings(max_examples=200 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MUTATION_SETTINGS = settings(max_examples=100 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])

scalars = st.one_of(
    st.none(), st.booleans(), st.integers(-20, 20), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12), st.sampled_from(["panda", "x", "z", "w", "parallel", "suction", "gripper",
                                           "pick_place", "panda_hand", "panda_joint1", ".nan", "1e999"]),
)
keys = st.one_of(st.sampled_from(FIELD_NAMES), st.text(max_size=8), st.integers(-3, 3), st.booleans())
documents = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=5), st.dictionaries(keys, inner, max_size=6)),
    max_leaves=30,
)


def check_text(text: str) -> None:
    """What ``robocfg validate FILE`` does, minus printing: must raise nothing but ConfigError."""
    path = Path(_TMP.name) / "doc.yaml"
    path.write_text(text, encoding="utf-8")
    try:
        kind = detect_kind(load_yaml(path))
        (load_robot if kind == "robot" else load_task)(path, strict=True)
    except ConfigError as exc:
        for p in exc.problems:  # every problem must format to FILE[:LINE[:COL]]: ...
            assert p.format().startswith(str(path))


@SETTINGS
@given(documents)
def test_random_documents_only_raise_config_error(data):
    check_text(yaml.safe_dump(data, allow_unicode=True))


@SETTINGS
@given(st.text(alphabet=st.sampled_from(list("ab:-[]{}&*!|>'\"#\n\t ?,.1%@`<")), max_size=60))
def test_random_text_only_raises_config_error(text):
    check_text(text)


def _paths(data, prefix=()):
    """Every (path, value) in nested data."""
    yield prefix, data
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _paths(v, (*prefix, k))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _paths(v, (*prefix, i))


def _mutate(base: dict, choice: int, action: str, value, new_key: str) -> dict:
    data = copy.deepcopy(base)
    paths = [p for p, _ in _paths(data) if p]
    path = paths[choice % len(paths)]
    parent = data
    for part in path[:-1]:
        parent = parent[part]
    last = path[-1]
    if action == "delete":
        del parent[last]
    elif action == "replace":
        parent[last] = value
    elif action == "add" and isinstance(parent, dict):
        parent[new_key] = value
    elif action == "wrap":
        parent[last] = [parent[last]]
    elif action == "duplicate" and isinstance(parent, list):
        parent.append(copy.deepcopy(parent[last]))
    return data


mutation = st.tuples(
    st.integers(0, 10_000),
    st.sampled_from(["delete", "replace", "add", "wrap", "duplicate"]),
    documents,
    st.sampled_from(FIELD_NAMES),
)


@MUTATION_SETTINGS
@given(st.lists(mutation, min_size=1, max_size=3))
def test_mutated_panda_only_raises_config_error(mutations):
    data = PANDA
    for m in mutations:
        data = _mutate(data, *m)
    check_text(yaml.safe_dump(data))


@MUTATION_SETTINGS
@given(st.lists(mutation, min_size=1, max_size=3))
def test_mutated_task_only_raises_config_error(mutations):
    data = TASK
    for m in mutations:
        data = _mutate(data, *m)
    check_text(yaml.safe_dump(data))


def test_unmutated_documents_are_valid():
    """The fuzz bases really are valid, so mutations start near the valid set."""
    check = Path(_TMP.name) / "base.yaml"
    check.write_text(yaml.safe_dump(PANDA))
    assert load_robot(check).config.name == "panda"
    check.write_text(yaml.safe_dump(TASK))
    assert load_task(check).config.task == "pick_place"


# Every other command's shipped task, mutated the same way: the command-block checks (waypoints,
# hold_object, meshes, grasp objects, names) must also answer with ConfigError only.
TASK_BASES = {stem: yaml.safe_load((ROOT / "robocfg" / "data" / "tasks" / f"{stem}.yaml").read_text())
              for stem in ("gripper", "trajectory", "follow_target_obstacle", "grasp")}
KIND_SETTINGS = settings(max_examples=40 * SCALE, deadline=None, suppress_health_check=[HealthCheck.too_slow])


@pytest.mark.parametrize("stem", sorted(TASK_BASES))
def test_mutated_task_kinds_only_raise_config_error(stem):
    @KIND_SETTINGS
    @given(st.lists(mutation, min_size=1, max_size=3))
    def run(mutations):
        data = TASK_BASES[stem]
        for m in mutations:
            data = _mutate(data, *m)
        check_text(yaml.safe_dump(data))

    run()


def test_unmutated_task_kinds_are_valid():
    check = Path(_TMP.name) / "kind.yaml"
    for stem, data in TASK_BASES.items():
        check.write_text(yaml.safe_dump(data))
        assert load_task(check).config.task in stem, stem
