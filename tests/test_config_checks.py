"""robocfg.checks: every URDF cross-check rule, as errors or warnings with their YAML location."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robocfg.checks import load_robot, load_task
from robocfg.config.overrides import ROBOT_OVERRIDE_SOURCE
from robocfg.errors import ConfigError

ROOT = Path(__file__).resolve().parent.parent
PANDA = (ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text()
DATA = ROOT / "tests" / "data"
JI = "    joint_indices: [0, 1, 2, 3, 4, 5, 6]\n"
R_PANDA = "R_ee_graspnet: [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]"


def write(tmp_path: Path, text: str, name: str = "robot.yaml") -> Path:
    f = tmp_path / name
    f.write_text(text)
    return f


def panda(tmp_path: Path, *subs: tuple[str, str]) -> Path:
    text = PANDA
    for old, new in subs:
        assert old in text, old
        text = text.replace(old, new, 1)
    return write(tmp_path, text)


def errors(path: Path, strict: bool = False) -> dict[str, str]:
    """path.to.field → message of every problem (ConfigError expected)."""
    with pytest.raises(ConfigError) as exc:
        load_robot(path, strict=strict)
    for p in exc.value.problems:
        assert p.line is not None and p.file == str(path)
    return {p.path: p.message for p in exc.value.problems}


def test_panda_is_valid_without_warnings():
    robot = load_robot(ROOT / "robocfg" / "data" / "robots" / "panda.yaml", strict=True)
    arm = robot.config.arm()
    assert robot.warnings == []
    assert robot.arm_joints(arm) == [f"panda_joint{i}" for i in range(1, 8)]
    assert robot.gripper_joints(arm) == ["panda_finger_joint1"]
    assert robot.mimic_followers(["panda_finger_joint1"]) == ["panda_finger_joint2"]
    assert robot.urdf_path.name == "panda.urdf"


def test_joints_by_indices_only(tmp_path):
    f = panda(tmp_path, ("    joints: [panda_joint1, panda_joint2, panda_joint3, panda_joint4, panda_joint5, panda_joint6, panda_joint7]\n", ""),
              ("      joints: [panda_finger_joint1]\n", ""))
    robot = load_robot(f)
    arm = robot.config.arm()
    assert robot.arm_joints(arm)[-1] == "panda_joint7"
    assert robot.gripper_joints(arm) == ["panda_finger_joint1"]


def test_unknown_link_and_joint_suggest(tmp_path):
    e = errors(panda(tmp_path, ("base_link: panda_link0", "base_link: panda_link_0"), ("panda_joint2,", "panda_joint_2,")))
    assert "did you mean 'panda_link0'?" in e["arms[0].base_link"]
    assert "did you mean 'panda_joint2'?" in e["arms[0].joints[1]"]


def test_index_rules(tmp_path):
    e = errors(panda(tmp_path, ("joint_indices: [0, 1, 2, 3, 4, 5, 6]", "joint_indices: [0, 1, 2, 3, 4, 6, 9]")))
    assert "'panda_joint7' but joints[5] is 'panda_joint6'" in e["arms[0].joint_indices[5]"]
    assert "out of range" in e["arms[0].joint_indices[6]"] and "0..8" in e["arms[0].joint_indices[6]"]


def test_pybullet_index_mistake_is_explained(tmp_path):
    e = errors(panda(tmp_path, ("gripper_indices: [7]", "gripper_indices: [8]")))
    msg = e["arms[0].gripper.gripper_indices[0]"]
    assert "panda_finger_joint2" in msg  # DOF 8 is the follower finger...
    assert "PyBullet joint index 8 is the fixed joint 'panda_hand_joint'" in msg  # ...and pybullet 8 is fixed


def test_fixed_joint_by_name(tmp_path):
    e = errors(panda(tmp_path, ("panda_joint7]", "panda_joint8]"), (JI, "")))
    assert "fixed, not movable" in e["arms[0].joints[6]"]


def test_chain_rules(tmp_path):
    e = errors(panda(tmp_path, ("panda_joint2, panda_joint3", "panda_joint3, panda_joint2"), (JI, "")))
    assert "serial chain" in e["arms[0].joints"]
    e = errors(panda(tmp_path, ("base_link: panda_link0", "base_link: panda_leftfinger")))
    assert "not below base_link" in e["arms[0].ee_link"]


def test_gripper_joint_must_not_move_ee_link(tmp_path):
    e = errors(panda(tmp_path, ("ee_link: panda_hand", "ee_link: panda_leftfinger")))
    assert "moves ee_link 'panda_leftfinger'" in e["arms[0].gripper.joints[0]"]


def test_gripper_joint_must_be_a_leader_not_a_mimic_follower(tmp_path):
    e = errors(panda(tmp_path, ("      joints: [panda_finger_joint1]\n", ""), ("gripper_indices: [7]", "gripper_indices: [8]")))
    assert "mimic follower of 'panda_finger_joint1'" in e["arms[0].gripper.gripper_indices[0]"]


def test_home_limits_error_and_std_warning(tmp_path):
    e = errors(panda(tmp_path, ("home: [0.0, -0.785,", "home: [0.0, -1.9,")))
    assert "outside the limits" in e["arms[0].home[1]"]
    robot = load_robot(panda(tmp_path, ("home_std: [0.1, 0.1,", "home_std: [0.1, 0.5,")))
    [w] = robot.warnings
    assert w.path == "arms[0].home_std[1]" and w.severity == "warning"
    assert "arms[0].home_std[1]" in errors(panda(tmp_path, ("home_std: [0.1, 0.1,", "home_std: [0.1, 0.5,")), strict=True)


@pytest.mark.parametrize(("R", "word"), [
    ("[[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 1e-3]]", "orthonormal"),
    ("[[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [-1.0, 0.0, 0.0]]", "det = -1"),
    ("[[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]", "column 2 (ee_axis 'z') must be (1, 0, 0)"),
])
def test_R_ee_graspnet_rules(tmp_path, R, word):
    e = errors(panda(tmp_path, (R_PANDA, f"R_ee_graspnet: {R}")))
    assert word in e["arms[0].R_ee_graspnet"]


def test_R_within_tolerance_is_accepted(tmp_path):
    load_robot(panda(tmp_path, (R_PANDA, "R_ee_graspnet: [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 1e-8]]")))


def test_R_ee_graspnet_convention_for_panda():
    """world_R_ee = world_R_grasp · R_ee_graspnet: the grasp x (approach) is the hand's +z."""
    robot = load_robot(ROOT / "robocfg" / "data" / "robots" / "panda.yaml")
    R = np.asarray(robot.config.arm().R_ee_graspnet)
    world_R_grasp = np.eye(3)  # approach along world x, closing along world y
    world_R_ee = world_R_grasp @ R
    assert np.allclose(world_R_ee[:, 2], [1, 0, 0])  # hand z (ee_axis) = approach
    assert np.allclose(world_R_ee[:, 1], [0, 1, 0])  # hand y = closing direction (fingers slide on y)


def test_tcp_offset_far_from_the_pads_warns_and_strict_fails(tmp_path):
    robot = load_robot(DATA / "panda_off_tcp.yaml")
    [w] = robot.warnings
    assert w.path == "arms[0].tcp_offset" and "0.1022 m along z" in w.message
    assert "arms[0].tcp_offset" in errors(DATA / "panda_off_tcp.yaml", strict=True)
    assert load_robot(panda(tmp_path, ("tcp_offset: 0.1034", "tcp_offset: 0.108"))).warnings == []  # within 10 mm


def test_ee_axis_not_towards_the_fingers_is_an_error(tmp_path):
    e = errors(panda(tmp_path, ("ee_axis: z", "ee_axis: y"), (R_PANDA, "R_ee_graspnet: [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]")))
    assert "towards the fingertips" in e["arms[0].ee_axis"]


def test_gripper_positions_within_limits(tmp_path):
    e = errors(panda(tmp_path, ("closed: [0.0]", "closed: [-0.01]")))
    assert "outside the limits" in e["arms[0].gripper.closed[0]"]


def test_gripper_model_rules(tmp_path):
    assert "same position" in errors(panda(tmp_path, ("open: [0.04]", "open: [0.0]")))["arms[0].gripper.open"]
    assert "must be < max_width" in errors(panda(tmp_path, ("min_width: 0.0", "min_width: 0.09")))["arms[0].gripper.min_width"]
    assert "one value per driven joint" in errors(panda(tmp_path, ("open: [0.04]", "open: [0.04, 0.04]")))["arms[0].gripper.open"]


def test_suction_gripper_link_must_be_rigid_below_ee(tmp_path):
    start, end = PANDA.index("    gripper:\n"), PANDA.index("    gripper_keypoints:")
    suction = "    gripper:\n      type: suction\n      link: {link}\n"
    ok = write(tmp_path, PANDA[:start] + suction.format(link="panda_grasptarget") + PANDA[end:])
    assert load_robot(ok).config.arm().gripper.type == "suction"
    bad = write(tmp_path, PANDA[:start] + suction.format(link="panda_leftfinger") + PANDA[end:])
    assert "rigidly attached" in errors(bad)["arms[0].gripper.link"]
    typo = write(tmp_path, PANDA[:start] + suction.format(link="panda_grasp_target") + PANDA[end:])
    assert "did you mean 'panda_grasptarget'?" in errors(typo)["arms[0].gripper.link"]


def test_drive_and_physics_names_are_checked(tmp_path):
    f = panda(tmp_path, ("drives:\n", "drives:\n  velocity_limits: {panda_joint_1: 1.0}\n"),
              ("physics:\n", "physics:\n  link_masses: {panda_lnk1: 1.0}\n"))
    e = errors(f)
    assert "did you mean 'panda_joint1'?" in e["drives.velocity_limits.panda_joint_1"]
    assert "did you mean 'panda_link1'?" in e["physics.link_masses.panda_lnk1"]


TWO_LINK_URDF = """<?xml version="1.0"?>
<robot name="two_link">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="arm"/>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j_tool" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0.2 0 0"/></joint>
</robot>
"""
TWO_LINK_YAML = """schema_version: 1
name: two_link
urdf: two_link.urdf
arms:
  - joints: [j1]
    base_link: base
    ee_link: tool
    tcp_offset: 0.05
    ee_axis: x
    R_ee_graspnet: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    home: [0.0]
"""


def test_every_link_without_inertial_warns_until_given_a_mass(tmp_path):
    """The moving 'arm' and the fixed-joint child 'tool' alike: each would load as 1 kg in PyBullet."""
    (tmp_path / "two_link.urdf").write_text(TWO_LINK_URDF)
    robot = load_robot(write(tmp_path, TWO_LINK_YAML))
    w_arm, w_tool = sorted(robot.warnings, key=lambda w: "'tool'" in w.message)
    assert w_arm.path == w_tool.path == "physics.link_masses"
    assert "'arm'" in w_arm.message and "'tool' has no <inertial>" in w_tool.message and "0.001 kg" in w_tool.message
    half = load_robot(write(tmp_path, TWO_LINK_YAML + "physics:\n  link_masses: {arm: 0.5}\n"))
    assert [w.message for w in half.warnings] == [w_tool.message]
    fixed = load_robot(write(tmp_path, TWO_LINK_YAML + "physics:\n  link_masses: {arm: 0.5, tool: 0.001}\n"))
    assert fixed.warnings == []


def test_package_uri_resolves_through_package_dirs(tmp_path):
    (tmp_path / "pkg" / "urdf").mkdir(parents=True)
    (tmp_path / "pkg" / "urdf" / "two_link.urdf").write_text(TWO_LINK_URDF)
    text = TWO_LINK_YAML.replace("urdf: two_link.urdf", "urdf: package://mypkg/urdf/two_link.urdf\npackage_dirs: {mypkg: pkg}")
    assert load_robot(write(tmp_path, text)).urdf_path == (tmp_path / "pkg" / "urdf" / "two_link.urdf").resolve()


def test_missing_mesh_lists_the_paths_tried(tmp_path):
    (tmp_path / "two_link.urdf").write_text(TWO_LINK_URDF.replace(
        '<link name="arm"/>', '<link name="arm"><visual><geometry><mesh filename="package://foo/arm.stl"/></geometry></visual></link>'))
    e = errors(write(tmp_path, TWO_LINK_YAML))
    msg = e["urdf"]
    assert "'package://foo/arm.stl'" in msg and "tried:" in msg and str(tmp_path / "foo" / "arm.stl") in msg


# ---------------------------------------------------------------- tasks


def task_errors(path: Path, **kw) -> list:
    with pytest.raises(ConfigError) as exc:
        load_task(path, **kw)
    return exc.value.problems


def test_task_loads_its_robots(tmp_path):
    task = load_task(DATA / "task_pick_place.yaml", strict=True)
    assert task.config.task == "pick_place" and [r.config.name for r in task.robots] == ["panda"]
    assert task.config.sim.timestep == pytest.approx(1 / 240)


def test_task_robot_override(tmp_path, monkeypatch):
    f = write(tmp_path, (DATA / "task_gripper.yaml").read_text(), "task.yaml")
    (tmp_path / "robots").mkdir()
    (tmp_path / "robots" / "other.yaml").write_text(PANDA.replace("name: panda", "name: other"))
    monkeypatch.chdir(tmp_path)  # ./robots is first on the search path
    assert load_task(f).robots[0].config.name == "panda"
    assert load_task(f, robot_override="other").robots[0].config.name == "other"
    [p] = task_errors(f, robot_override="othr")
    # blamed on the name given, not on the file's robot line that it replaces
    assert (p.file, p.line, p.path) == (ROBOT_OVERRIDE_SOURCE, None, "othr")
    assert p.message.startswith("unknown robot; did you mean 'other'?")


def test_task_nested_robot_problems_keep_their_own_file(tmp_path):
    bad_robot = panda(tmp_path, ("ee_link: panda_hand", "ee_link: panda_hnd"))
    f = write(tmp_path, (DATA / "task_gripper.yaml").read_text().replace("- robot: panda", f"- robot_config_file: {bad_robot.name}"), "task.yaml")
    probs = task_errors(f)
    assert probs[0].file == str(f) and probs[0].path == "robots[0].robot_config_file"
    assert any(p.file == str(bad_robot.resolve()) and p.path == "arms[0].ee_link" for p in probs)


def pick_place_text() -> str:
    return (DATA / "task_pick_place.yaml").read_text().replace("../../robocfg/data/robots/panda.yaml", str(ROOT / "robocfg" / "data" / "robots" / "panda.yaml"))


def test_pick_place_checks(tmp_path):
    text = pick_place_text()
    wide = write(tmp_path, text.replace("size: [0.04, 0.04, 0.04]", "size: [0.09, 0.2, 0.04]"), "wide.yaml")
    [p] = task_errors(wide)
    assert p.path == "pick_place.object.size" and "90.0 mm" in p.message
    rotated_ok = write(tmp_path, text.replace("size: [0.04, 0.04, 0.04]", "size: [0.2, 0.05, 0.04]"), "long.yaml")
    load_task(rotated_ok)  # 5 cm across its narrow side fits an 8 cm gripper
    nogrip = write(tmp_path, text.replace(f"robot_config_file: {ROOT / 'robocfg' / 'data' / 'robots' / 'panda.yaml'}", f"robot_config_file: {DATA / 'panda_no_gripper.yaml'}"), "ng.yaml")
    [p] = task_errors(nogrip)
    assert p.path == "robots[0]" and "no gripper" in p.message


def test_place_inside_obstacle_warns(tmp_path):
    text = pick_place_text().replace(
        "scene:\n", "scene:\n  obstacles:\n    - {name: wall, size: [0.1, 0.1, 0.3], position: [0.5, 0.3, 0.15], mass: 0}\n")
    f = write(tmp_path, text, "obst.yaml")
    [w] = load_task(f).warnings
    assert w.path == "pick_place.place_position" and "wall" in w.message
    [p] = task_errors(f, strict=True)
    assert p.severity == "warning"
