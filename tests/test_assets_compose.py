"""robocfg.assets.compose: arm + attachments → one cached URDF, names prefixed only where they clash."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from robocfg.assets.compose import CompositionError, Part, compose
from robocfg.assets.paths import Resolver
from robocfg.assets.urdf_xml import parse_urdf
from robocfg.checks import load_robot
from robocfg.errors import ConfigError
from robocfg.geometry import rpy_matrix

ROOT = Path(__file__).resolve().parent.parent

ARM = """<robot name="arm">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="base_link"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="link1"><visual><geometry><mesh filename="meshes/box.obj"/></geometry><material name="grey"/></visual></link>
  <link name="tool0"/>
  <joint name="j1" type="revolute"><parent link="base_link"/><child link="link1"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="1"/></joint>
  <joint name="flange" type="fixed"><parent link="link1"/><child link="tool0"/><origin xyz="0.2 0 0" rpy="0 1.5707963 0"/></joint>
</robot>
"""

GRIPPER = """<robot name="gripper">
  <material name="grey"><color rgba="0.1 0.1 0.1 1"/></material>
  <link name="base_link"><visual><geometry><mesh filename="../meshes/box.obj"/></geometry><material name="grey"/></visual></link>
  <link name="finger_a"/>
  <link name="finger_b"/>
  <joint name="j1" type="prismatic"><parent link="base_link"/><child link="finger_a"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
  <joint name="finger_b_joint" type="prismatic"><parent link="base_link"/><child link="finger_b"/><axis xyz="-1 0 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/><mimic joint="j1" multiplier="1"/></joint>
  <transmission name="t"><joint name="j1"/></transmission>
</robot>
"""

OBJ = "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n"


@pytest.fixture
def files(tmp_path, monkeypatch):
    """An arm, a gripper (in a subfolder, meshes relative to it) and a private cache folder."""
    monkeypatch.setenv("ROBOCFG_CACHE_DIR", str(tmp_path / "cache"))
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "box.obj").write_text(OBJ)
    (tmp_path / "gripper" / "urdf").mkdir(parents=True)
    (tmp_path / "gripper" / "meshes").mkdir()
    (tmp_path / "gripper" / "meshes" / "box.obj").write_text(OBJ)
    (tmp_path / "arm.urdf").write_text(ARM)
    (tmp_path / "gripper" / "urdf" / "gripper.urdf").write_text(GRIPPER)
    return tmp_path


def _part(tmp: Path, **kw) -> Part:
    return Part(tmp / "gripper" / "urdf" / "gripper.urdf", kw.pop("mount_link", "tool0"), **kw)


def test_clashing_names_prefixed_references_follow(files):
    out = compose(files / "arm.urdf", [_part(files)], Resolver(files))
    u = parse_urdf(out.path)
    assert out.path.parent == files / "cache" / "urdf"
    assert {"base_link", "link1", "tool0", "gripper_base_link", "finger_a", "finger_b"} == set(u.links)
    assert {"j1", "gripper_j1", "finger_b_joint", "gripper_mount"} <= set(u.joints)
    assert out.renamed == [{"base_link": "gripper_base_link", "j1": "gripper_j1", "grey": "gripper_grey"}]
    # parent/child and mimic references follow the renames; the arm keeps its names
    assert u.joints["gripper_j1"].parent == "gripper_base_link"
    assert u.joints["finger_b_joint"].mimic.joint == "gripper_j1"
    assert u.joints["j1"].child == "link1"
    assert u.root == "base_link"
    assert u.dof_joints == ["j1", "gripper_j1", "finger_b_joint"]
    text = out.path.read_text()
    assert '<joint name="gripper_j1" />' in text or '<joint name="gripper_j1"/>' in text  # transmission
    assert 'material name="gripper_grey"' in text
    # every mesh path is absolute and exists
    for link in u.links.values():
        for g in (*link.visuals, *link.collisions):
            assert Path(g.filename).is_absolute() and Path(g.filename).is_file()


def test_mount_pose_is_applied(files):
    xyz, rpy = (0.01, -0.02, 0.03), (0.1, -0.2, math.pi / 2)
    u = parse_urdf(compose(files / "arm.urdf", [_part(files, mount_xyz=xyz, mount_rpy=rpy)], Resolver(files)).path)
    q = {"j1": 0.7}
    T_rel = np.linalg.inv(u.link_pose("tool0", q)) @ u.link_pose("gripper_base_link", q)
    assert np.allclose(T_rel[:3, 3], xyz, atol=1e-12)
    assert np.allclose(T_rel[:3, :3], rpy_matrix(*rpy), atol=1e-12)


def test_explicit_prefix_renames_everything_and_chains(files):
    parts = [_part(files, prefix="left_"), _part(files, mount_link="left_finger_a", prefix="right_", name="second")]
    u = parse_urdf(compose(files / "arm.urdf", parts, Resolver(files)).path)
    assert {"left_base_link", "left_finger_a", "right_base_link", "right_finger_b"} <= set(u.links)
    assert u.joints["left_finger_b_joint"].mimic.joint == "left_j1"
    assert u.joints["second_mount"].parent == "left_finger_a"
    assert u.joints["second_mount"].child == "right_base_link"


def test_same_inputs_same_file_changed_inputs_new_file(files):
    a = compose(files / "arm.urdf", [_part(files)], Resolver(files)).path
    mtime = a.stat().st_mtime_ns
    assert compose(files / "arm.urdf", [_part(files)], Resolver(files)).path == a
    assert a.stat().st_mtime_ns == mtime  # not rewritten
    b = compose(files / "arm.urdf", [_part(files, mount_xyz=(0, 0, 0.01))], Resolver(files)).path
    assert b != a and a.is_file()


def test_problems_name_the_attachment(files):
    with pytest.raises(CompositionError) as exc:
        compose(files / "arm.urdf", [_part(files, mount_link="tool_0")], Resolver(files))
    (pr,) = exc.value.problems
    assert (pr.index, pr.key) == (0, "mount_link") and "did you mean 'tool0'" in pr.message
    (files / "gripper" / "meshes" / "box.obj").unlink()
    with pytest.raises(CompositionError) as exc:
        compose(files / "arm.urdf", [_part(files)], Resolver(files))
    assert [(p.index, p.key) for p in exc.value.problems] == [(0, "urdf")]
    assert "box.obj" in exc.value.problems[0].message


ROBOT_YAML = """schema_version: 1
name: composed
urdf: arm.urdf
attachments:
  - urdf: {gripper}
    mount_link: {mount}
    mount_rpy_deg: [0, 0, 90]
arms:
  - joints: [j1]
    base_link: base_link
    ee_link: gripper_base_link
    tcp_offset: 0.05
    ee_axis: z
    R_ee_graspnet: [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
    home: [0.0]
physics:
  link_masses: {{link1: 0.5, tool0: 0.001, gripper_base_link: 0.1, finger_a: 0.01, finger_b: 0.01}}
"""


def test_robot_yaml_uses_the_composed_urdf(files):
    f = files / "robot.yaml"
    f.write_text(ROBOT_YAML.format(gripper="gripper/urdf/gripper.urdf", mount="tool0"))
    before = [*sorted(p.name for p in files.iterdir()), "cache"]
    robot = load_robot(f, strict=True)
    assert robot.urdf_path.parent == files / "cache" / "urdf"
    assert "gripper_base_link" in robot.urdf.links and "gripper_mount" in robot.urdf.joints
    assert sorted(p.name for p in files.iterdir()) == sorted(before)  # nothing written next to the YAML


def test_kinematics_and_pybullet_load_the_composed_urdf(files):
    from robocfg.kinematics.model import KinematicModel

    f = files / "robot.yaml"
    f.write_text(ROBOT_YAML.format(gripper="gripper/urdf/gripper.urdf", mount="tool0"))
    robot = load_robot(f)
    model = KinematicModel.from_robot(robot)
    q = np.array([0.4])
    T = model.fk(q, "ee")
    assert np.allclose(T, robot.urdf.link_pose("gripper_base_link", {"j1": 0.4}), atol=1e-9)
    import pybullet as p

    from robocfg.sim.loading import load_robot_urdf
    cid = p.connect(p.DIRECT)
    try:
        body = load_robot_urdf(cid, robot, [0, 0, 0], [0, 0, 0, 1], 0)
        names = [p.getJointInfo(body, i, physicsClientId=cid)[1].decode() for i in range(p.getNumJoints(body, physicsClientId=cid))]
        assert "gripper_mount" in names and "gripper_j1" in names
    finally:
        p.disconnect(cid)


@pytest.mark.parametrize(("gripper", "mount", "where", "needle"), [
    ("gripper/urdf/gripper.urdf", "tool_0", "attachments[0].mount_link", "did you mean 'tool0'"),
    ("gripper/urdf/nope.urdf", "tool0", "attachments[0].urdf", "URDF not found"),
])
def test_attachment_errors_have_yaml_lines(files, gripper, mount, where, needle):
    f = files / "robot.yaml"
    f.write_text(ROBOT_YAML.format(gripper=gripper, mount=mount))
    with pytest.raises(ConfigError) as exc:
        load_robot(f)
    (pr,) = exc.value.problems
    assert pr.path == where and needle in pr.message
    assert pr.file == str(f) and pr.line == (6 if where.endswith("mount_link") else 5)


def test_shipped_ur5e_composition():
    robot = load_robot(ROOT / "robocfg" / "data" / "robots" / "ur5e_robotiq_2f85.yaml")
    u = robot.urdf
    assert {"robotiq_2f_85_base_link", "finger_joint", "left_inner_finger_pad", "tool0"} <= set(u.links) | set(u.joints)
    assert robot.mimic_followers(["finger_joint"]) == [
        "left_inner_finger_joint", "left_inner_knuckle_joint", "right_outer_knuckle_joint",
        "right_inner_finger_joint", "right_inner_knuckle_joint"]
    assert u.joints["robotiq_2f_85_mount"].parent == "tool0"


def test_editing_an_attachment_urdf_recomposes_in_the_same_process(files):
    import os

    f = files / "robot.yaml"
    f.write_text(ROBOT_YAML.format(gripper="gripper/urdf/gripper.urdf", mount="tool0"))
    first = load_robot(f)
    g = files / "gripper" / "urdf" / "gripper.urdf"
    g.write_text(GRIPPER.replace('<link name="finger_b"/>', '<link name="finger_b"/>\n  <link name="tip"/>')
                 .replace("</robot>", '  <joint name="tip_joint" type="fixed"><parent link="finger_b"/><child link="tip"/></joint>\n</robot>'))
    os.utime(g, ns=(first.urdf_path.stat().st_mtime_ns + 10**9,) * 2)
    second = load_robot(f)
    assert "tip" not in first.urdf.links and "tip" in second.urdf.links
    assert second.urdf_path != first.urdf_path
