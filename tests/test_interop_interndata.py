"""robocfg ↔ InternDataEngine robot configs: round trips, their template by hand, their documented mistakes."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
import yaml
from _cli import run_main

from robocfg.assets.paths import Resolver
from robocfg.checks import CheckedRobot, load_robot
from robocfg.config.catalog import BUILTIN_DIR
from robocfg.errors import ConfigError
from robocfg.interop.interndata_export import export_interndata
from robocfg.interop.interndata_import import import_interndata
from robocfg.interop.isaac_order import isaac_dof_order

DATA = Path(__file__).resolve().parent / "interndata"  # not in tests/data, which `validate` reads as robocfg YAMLs
PANDA_THEIRS = DATA / "panda.yaml"
BUILTINS = sorted(p.stem for p in (BUILTIN_DIR / "robots").glob("*.yaml"))


def _normalised(r: CheckedRobot) -> dict:
    """The robot as data, with URDF paths resolved and joints by name (indices are a spelling)."""
    res = Resolver(r.path.parent, r.config.package_dirs)
    d = r.config.model_dump()
    d.pop("name")
    d["urdf"] = str(res.urdf(r.config.urdf))
    for a in d["attachments"]:
        a["urdf"] = str(res.urdf(a["urdf"]))
    for dumped, arm in zip(d["arms"], r.config.arms, strict=True):
        dumped["joints"], dumped["joint_indices"] = r.arm_joints(arm), None
        if dumped["gripper"] and dumped["gripper"]["type"] == "parallel":
            dumped["gripper"]["joints"], dumped["gripper"]["gripper_indices"] = r.gripper_joints(arm), None
    return d


def _export(name: str, tmp_path: Path) -> tuple[CheckedRobot, Path]:
    robot = load_robot(BUILTIN_DIR / "robots" / f"{name}.yaml")
    out = tmp_path / "theirs" / f"{name}.yaml"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(export_interndata(robot, out).text)
    return robot, out


@pytest.mark.parametrize("name", BUILTINS)
def test_round_trip_gives_the_same_robot(name, tmp_path):
    robot, theirs = _export(name, tmp_path)
    back = import_interndata(theirs, tmp_path / "ours" / f"{name}.yaml").robot
    assert _normalised(back) == _normalised(robot)
    assert back.urdf.dof_joints == robot.urdf.dof_joints
    # Their keys, not the robocfg: block, carry what their format can say.
    data = yaml.safe_load(theirs.read_text())
    for arm in data["robocfg"].get("arms", []):
        assert not {"joints", "base_link", "ee_link", "home", "tcp_offset", "ee_axis", "R_ee_graspnet"} & set(arm)
    isaac = isaac_dof_order(robot.urdf)
    for side, arm in zip(["left", "right"], robot.config.arms, strict=False):
        assert [isaac[i] for i in data[f"{side}_joint_indices"]] == robot.arm_joints(arm)
        assert data[f"{side}_joint_home"] == list(arm.home)


def _assert_same_arms(robot: CheckedRobot, back: CheckedRobot) -> None:
    """Every arm field their keys carry, and the gripper robocfg completes from the URDF, agree."""
    assert len(back.config.arms) == len(robot.config.arms)
    for a, b in zip(robot.config.arms, back.config.arms, strict=True):
        assert back.arm_joints(b) == robot.arm_joints(a)
        for key in ("name", "base_link", "ee_link", "tcp_offset", "ee_axis", "R_ee_graspnet", "home", "home_std",
                    "collision_filter"):
            assert getattr(b, key) == getattr(a, key), key
        if a.gripper_keypoints is not None:
            assert b.gripper_keypoints == a.gripper_keypoints
        assert back.gripper_joints(b) == robot.gripper_joints(a)
        for key in ("open", "closed", "max_width", "min_width"):
            assert getattr(b.gripper, key) == getattr(a.gripper, key), key
        assert sorted(b.gripper.finger_links) == sorted(a.gripper.finger_links)  # the pair, found from the geometry


@pytest.mark.parametrize("name", ["panda", "dual_panda", "ur5e_robotiq_2f85"])
def test_their_keys_alone_give_the_same_arms(name, tmp_path):
    """Without our block (a file from their users), --urdf and their keys give the same arms."""
    robot, theirs = _export(name, tmp_path)
    data = yaml.safe_load(theirs.read_text())
    data.pop("robocfg")
    theirs.write_text(yaml.safe_dump(data, sort_keys=False))
    _assert_same_arms(robot, import_interndata(theirs, tmp_path / "ours" / f"{name}.yaml", str(robot.urdf_path)).robot)


@pytest.mark.parametrize("name", ["panda", "dual_panda", "ur5e_robotiq_2f85", "xarm6"])
def test_hand_written_files_give_the_built_in_arms(name, tmp_path):
    """tests/interndata/NAME.yaml, written from their template, on the URDF robocfg uses for NAME."""
    robot = load_robot(BUILTIN_DIR / "robots" / f"{name}.yaml")
    result = import_interndata(DATA / f"{name}.yaml", tmp_path / f"{name}.yaml", str(robot.urdf_path))
    _assert_same_arms(robot, result.robot)
    assert not result.warnings


def test_dual_arm_indices_interleave_in_isaac_order(tmp_path):
    _, theirs = _export("dual_panda", tmp_path)
    data = yaml.safe_load(theirs.read_text())
    assert data["left_joint_indices"] == [0, 2, 4, 6, 8, 10, 12]
    assert data["right_joint_indices"] == [1, 3, 5, 7, 9, 11, 13]
    assert data["fl_ee_path"] == "left_panda_hand" and data["fr_ee_path"] == "right_panda_hand"


def test_hand_written_template_file_imports(tmp_path):
    result = import_interndata(PANDA_THEIRS, tmp_path / "franka.yaml", "pybullet_data://franka_panda/panda.urdf")
    arm = result.robot.config.arms[0]
    ref = load_robot(BUILTIN_DIR / "robots" / "panda.yaml").config.arms[0]
    assert result.robot.arm_joints(arm) == list(ref.joints or [])
    assert arm.gripper is not None and arm.gripper.joints == ["panda_finger_joint1"]  # type: ignore[union-attr]
    assert arm.gripper.closed == [0.0] and arm.gripper.finger_links == ref.gripper.finger_links  # type: ignore[union-attr]
    assert result.robot.config.physics.solver_iterations == 128
    dropped = {d.key: d.why for d in result.dropped}
    assert "panda_finger_joint2" in dropped["left_gripper_indices"]
    assert {"target_class", "path", "robot_file", "stabilization_threshold"} <= set(dropped)


def _variant(tmp_path: Path, old: str, new: str) -> tuple[Path, int]:
    """Their Panda file with one edit, and the 1-based line of the edit."""
    text = PANDA_THEIRS.read_text()
    assert old in text
    line = text[: text.index(old)].count("\n") + 1
    p = tmp_path / "their_panda.yaml"
    p.write_text(text.replace(old, new, 1))
    return p, line


def _errors(path: Path, tmp_path: Path) -> list[str]:
    with pytest.raises(ConfigError) as exc:
        import_interndata(path, tmp_path / "out" / "robot.yaml", "pybullet_data://franka_panda/panda.urdf")
    assert not (tmp_path / "out" / "robot.yaml").exists()
    return [p.format() for p in exc.value.problems]


@pytest.mark.parametrize(("old", "new", "field", "words"), [
    ("tcp_offset: 0.1034", "tcp_offset: -0.1034", "tcp_offset", "must be positive"),
    ("[-1.0, 0.0, 0.0]]", "[-1.0, 0.0, 0.5]]", "R_ee_graspnet", "rotation matrix"),
    ('ee_axis: "z"', 'ee_axis: "x"', "ee_axis", "column 0 of R_ee_graspnet"),
    ('fl_ee_path: "panda_hand"', 'fl_ee_path: "panda_leftfinger"', "fl_ee_path", "must be fixed"),
    ('fl_base_path: "panda_link0"', 'fl_base_path: "panda_lnk0"', "fl_base_path", "did you mean 'panda_link0'"),
    ("left_joint_indices: [0, 1, 2, 3, 4, 5, 6]", "left_joint_indices: [0, 1, 2, 3, 4, 5, 9]", "left_joint_indices",
     "out of range"),
    ("tool_head: [0.0, 0.0, 0.1034, 1]", "tool_head: [0.1034, 0.0, 0.0, 1]", "fl_gripper_keypoints.tool_head",
     "away from +z"),
    ("tcp_offset: 0.1034", "tcp_ofset: 0.1034", "tcp_ofset", "did you mean 'tcp_offset'"),
])
def test_their_mistakes_are_errors_at_their_lines(tmp_path, old, new, field, words):
    path, line = _variant(tmp_path, old, new)
    errors = _errors(path, tmp_path)
    hit = [e for e in errors if re.search(rf": {re.escape(field)}[:\[.]", e) and words in e]
    assert hit, errors
    assert hit[0].startswith(f"{path}:{line}:"), hit[0]


def test_wrong_ee_axis_with_a_consistent_rotation_is_caught_by_the_finger_check(tmp_path):
    """ee_axis 'x' with an R_ee_graspnet that agrees and no keypoints: only the URDF shows the fingers lie along z."""
    text = PANDA_THEIRS.read_text()
    text = re.sub(r"fl_gripper_keypoints:\n(  .*\n)+", "", text)
    text = text.replace('ee_axis: "z"', 'ee_axis: "x"').replace(
        "R_ee_graspnet: [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]",
        "R_ee_graspnet: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]")
    p = tmp_path / "their_panda.yaml"
    p.write_text(text)
    line = text[: text.index('ee_axis: "x"')].count("\n") + 1
    errors = _errors(p, tmp_path)
    assert any(e.startswith(f"{p}:{line}:") and "ee_axis" in e and "finger pads" in e for e in errors), errors


def test_urdf_order_indices_get_a_hint(tmp_path):
    """Dual-arm: the URDF (PyBullet) order is not Isaac's; indices written in it are named as such."""
    robot, theirs = _export("dual_panda", tmp_path)
    urdf_order = robot.urdf.dof_joints
    text = theirs.read_text()
    left = [urdf_order.index(j) for j in robot.arm_joints(robot.config.arms[0])]
    text = text.replace("left_joint_indices: [0, 2, 4, 6, 8, 10, 12]", f"left_joint_indices: {left}")
    theirs.write_text(text)
    with pytest.raises(ConfigError) as exc:
        import_interndata(theirs, tmp_path / "ours.yaml")
    [msg] = [p.format() for p in exc.value.problems]
    assert "left_joint_indices" in msg and "URDF-order" in msg and "breadth-first" in msg


def test_cli_import_export_and_no_overwrite(tmp_path, capsys, monkeypatch):
    shutil.copy(PANDA_THEIRS, tmp_path / "their_panda.yaml")
    args = ["import", "interndata", "their_panda.yaml", "--urdf", "pybullet_data://franka_panda/panda.urdf", "-o", "mine.yaml"]
    code, out, err = run_main(args, capsys, monkeypatch, tmp_path)
    assert code == 0, err
    assert "dropped path:" in out and "validate: ok" in out
    code, out, err = run_main(args, capsys, monkeypatch, tmp_path)
    assert code == 2 and "exists; pass --force" in err
    assert run_main([*args, "--force"], capsys, monkeypatch, tmp_path)[0] == 0
    code, out, err = run_main(["export", "interndata", "mine.yaml", "-o", "back.yaml"], capsys, monkeypatch, tmp_path)
    assert code == 0, err
    assert "#   [x] Calculate R_ee_graspnet" in (tmp_path / "back.yaml").read_text()
    assert run_main(["export", "interndata", "mine.yaml", "-o", "back.yaml"], capsys, monkeypatch, tmp_path)[0] == 2
    bad = (tmp_path / "their_panda.yaml").read_text().replace("tcp_offset: 0.1034", "tcp_offset: -0.1")
    (tmp_path / "bad.yaml").write_text(bad)
    code, out, err = run_main(["import", "interndata", "bad.yaml", "--urdf", "pybullet_data://franka_panda/panda.urdf",
                               "-o", "bad_out.yaml"], capsys, monkeypatch, tmp_path)
    assert code == 2 and re.search(r"^bad\.yaml:\d+:\d+: tcp_offset: must be positive", err, re.M), err
    assert "Traceback" not in err and not (tmp_path / "bad_out.yaml").exists()


def test_doc_commands_run(tmp_path, capsys, monkeypatch):
    """docs/coming-from-interndataengine.md: every command it shows runs and succeeds, in order."""
    doc = (Path(__file__).resolve().parent.parent / "docs" / "coming-from-interndataengine.md").read_text()
    commands = re.findall(r"^\$ robocfg (.+)$", doc, re.M)
    assert len(commands) >= 4
    shutil.copy(PANDA_THEIRS, tmp_path / "their_panda.yaml")
    for command in commands:
        code, out, err = run_main(command.split(), capsys, monkeypatch, tmp_path)
        assert code == 0, (command, out, err)
    assert (tmp_path / "robots" / "panda_again.yaml").is_file()


def test_keys_outside_their_template_are_dropped(tmp_path):
    p, _ = _variant(tmp_path, "lift_home: []", "lift_home: []\nsim_camera_mount: head_link")
    result = import_interndata(p, tmp_path / "out.yaml", "pybullet_data://franka_panda/panda.urdf")
    assert "template" in {d.key: d.why for d in result.dropped}["sim_camera_mount"]


@pytest.mark.parametrize(("index", "owner"), [(0, "a left arm joint"), (7, "a left gripper joint")])
def test_lift_joints_must_be_outside_the_arms(tmp_path, index, owner):
    p, line = _variant(tmp_path, "lift_indices: []", f"lift_indices: [{index}]\n")
    errors = _errors(p, tmp_path)
    assert any(e.startswith(f"{p}:{line}:") and "lift_indices[0]" in e and owner in e for e in errors), errors


def test_block_needs_one_entry_per_arm(tmp_path):
    _, theirs = _export("dual_panda", tmp_path)
    data = yaml.safe_load(theirs.read_text())
    data["robocfg"]["arms"] = data["robocfg"]["arms"][:1]
    theirs.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(ConfigError) as exc:
        import_interndata(theirs, tmp_path / "ours.yaml")
    assert "one entry per arm (2: left, right)" in str(exc.value)
