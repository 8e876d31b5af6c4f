"""`robocfg new-robot`: drafts from URDFs validate and match the hand-written robot YAMLs."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest
import yaml
from _cli import run_main
from _sim_helpers import make_task

from robocfg.assets.draft import draft_robot
from robocfg.assets.draft_yaml import render_yaml
from robocfg.assets.urdf_xml import parse_urdf
from robocfg.checks import load_robot

ROOT = Path(__file__).resolve().parent.parent
PANDA_URDF = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
IIWA_URDF = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
KR210_URDF = ROOT / "robocfg" / "data" / "robots" / "kuka_kr210" / "kuka_kr210.urdf"


def test_panda_draft_matches_the_shipped_yaml(tmp_path, capsys, monkeypatch):
    code, out, _ = run_main(["new-robot", str(PANDA_URDF)], capsys, monkeypatch, tmp_path)
    assert code == 0, out
    assert "validate: ok" in out and "still to check" in out
    draft_path = tmp_path / "robots" / "panda.yaml"
    draft = load_robot(draft_path)  # the draft validates without errors
    assert draft.warnings == []
    got, want = draft.config.arms[0], load_robot(ROOT / "robocfg" / "data" / "robots" / "panda.yaml").config.arms[0]
    assert got.joints == want.joints
    assert (got.base_link, got.ee_link, got.ee_axis) == (want.base_link, want.ee_link, want.ee_axis)
    assert got.tcp_offset == pytest.approx(want.tcp_offset, abs=0.002)
    assert np.allclose(got.R_ee_graspnet, want.R_ee_graspnet)
    g, w = got.gripper, want.gripper
    assert g.joints == w.joints and g.open == w.open and g.closed == w.closed
    assert sorted(g.finger_links) == sorted(w.finger_links)
    assert g.max_width == pytest.approx(w.max_width, abs=0.002)
    # home is inside the limits (validate checked) and the marked guesses are in the file
    assert "CHECK" in draft_path.read_text()
    assert yaml.safe_load(draft_path.read_text())["urdf"] == "pybullet_data://franka_panda/panda.urdf"


def test_never_overwrites_without_force(tmp_path, capsys, monkeypatch):
    target = tmp_path / "mine.yaml"
    target.write_text("keep me\n")
    code, _, err = run_main(["new-robot", str(PANDA_URDF), "-o", str(target)], capsys, monkeypatch, tmp_path)
    assert code == 2 and "--force" in err
    assert target.read_text() == "keep me\n"
    code, out, _ = run_main(["new-robot", str(PANDA_URDF), "-o", str(target), "--force"], capsys, monkeypatch, tmp_path)
    assert code == 0, out
    assert load_robot(target).config.name == "mine"


def test_arm_without_gripper_and_a_relative_urdf(tmp_path):
    d = draft_robot(parse_urdf(IIWA_URDF), "iiwa", tmp_path)
    assert d.gripper is None and len(d.arm_joints) == 7 and d.ee_link == "lbr_iiwa_link_7"
    assert any("no gripper" in n for n in d.notes)
    # A URDF outside the known packages is referenced relative to the YAML's folder.
    d = draft_robot(parse_urdf(KR210_URDF), "kr", tmp_path / "robots")
    out = tmp_path / "robots" / "kr.yaml"
    out.parent.mkdir()
    out.write_text(render_yaml(d))
    robot = load_robot(out)
    assert robot.urdf_path == KR210_URDF.resolve()
    assert robot.config.arms[0].joints == [f"joint_a{i}" for i in range(1, 7)]
    # No gripper joints: the tool tip (the cup face, furthest from the wrist) measured from the deepest
    # frame whose + axis points at it — the shipped kuka_kr210.yaml's ee_link, TCP and suction link.
    assert robot.config.arms[0].ee_link == "tool0" and robot.config.arms[0].ee_axis == "z"
    assert robot.config.arms[0].tcp_offset == pytest.approx(0.2, abs=1e-4)
    assert d.suction_link == "suction_cup" and "# gripper: {type: suction, link: suction_cup" in out.read_text()
    lo = [robot.urdf.joints[j].lower for j in robot.config.arms[0].joints]
    hi = [robot.urdf.joints[j].upper for j in robot.config.arms[0].joints]
    assert all(a <= h <= b for a, h, b in zip(lo, robot.config.arms[0].home, hi, strict=True))


def test_composed_robot_draft_reproduces_the_shipped_tcp(tmp_path, capsys, monkeypatch):
    """`new-robot` on urdf + attachments (the UR5e + Robotiq 2F-85 of the library): the TCP point
    (tool0 frame, by FK at home) lies within 2 mm of the shipped YAML's, and the home found by IK
    points the tool straight down."""
    parts = tmp_path / "parts.yaml"
    parts.write_text("urdf: airo_models://ur5e\nattachments:\n  - urdf: airo_models://robotiq_2f_85\n    mount_link: tool0\n")
    code, out, _ = run_main(["new-robot", str(parts), "-o", str(tmp_path / "ur5e_2f85.yaml")], capsys, monkeypatch, tmp_path)
    assert code == 0, out
    assert "gripper parallel ['finger_joint']" in out
    draft = load_robot(tmp_path / "ur5e_2f85.yaml")
    shipped = load_robot(ROOT / "robocfg" / "data" / "robots" / "ur5e_robotiq_2f85.yaml")
    assert draft.config.attachments[0].urdf == "airo_models://robotiq_2f_85" and draft.config.urdf == "airo_models://ur5e"
    got, want = draft.config.arms[0], shipped.config.arms[0]

    def tcp_in_tool0(robot, arm) -> np.ndarray:
        T = np.linalg.inv(robot.urdf.link_pose("tool0")) @ robot.urdf.link_pose(arm.ee_link)
        axis = "xyz".index(arm.ee_axis)
        return T[:3, 3] + arm.tcp_offset * T[:3, axis]

    assert np.linalg.norm(tcp_in_tool0(draft, got) - tcp_in_tool0(shipped, want)) < 0.002
    q = dict(zip(got.joints, got.home, strict=True))
    tool_z = (draft.urdf.link_pose(got.ee_link, q))[:3, "xyz".index(got.ee_axis)]
    assert tool_z[2] < -0.999  # approach axis straight down
    # fingers closing along world -y: the tool frame of the default tasks' [180, 0, 0] (follow-target starts there)
    R_grasp = draft.urdf.link_pose(got.ee_link, q)[:3, :3] @ np.asarray(got.R_ee_graspnet).T
    assert R_grasp[1, 1] < -0.999
    # no arm link under the plane the robot stands on (the drafted UR10 got an elbow-down home 0.21 m into the floor)
    assert min(draft.urdf.link_pose(link, q)[2, 3] for link in ("upper_arm_link", "forearm_link", "wrist_1_link")) > 0.0
    assert all(n in draft.config.physics.link_masses for n in ("left_inner_finger_pad", "robotiq_2f_85_base_link", "tool0"))


def test_one_jaw_gripper_is_detected_not_taken_for_an_arm_joint(tmp_path):
    d = draft_robot(parse_urdf(ROOT / "tests" / "data" / "sim_onejaw.urdf"), "onejaw", tmp_path)
    assert d.arm_joints == ["j1", "j2", "j3", "j4", "j5", "j6"]
    g = d.gripper
    assert g.kind == "one_jaw" and g.joints == ["jaw"] and g.finger_links == ["moving_jaw", "fixed_jaw"]
    assert g.fixed_jaw_face == pytest.approx(0.02, abs=1e-4) and g.max_width == pytest.approx(0.08, abs=1e-4)
    assert d.tcp_offset == pytest.approx(0.09, abs=1e-4) and d.ee_axis == "z"
    assert d.link_masses == {"tool0": 0.001}
    out = tmp_path / "onejaw.yaml"
    out.write_text(render_yaml(d))
    assert load_robot(out).warnings == []


def test_drafted_panda_runs_gripper_and_pick_place(tmp_path, capsys, monkeypatch):
    code, out, _ = run_main(["new-robot", str(PANDA_URDF), "-o", str(tmp_path / "p.yaml")], capsys, monkeypatch, tmp_path)
    assert code == 0, out
    code, _, err = run_main(["run", "gripper", "--robot", str(tmp_path / "p.yaml"), "-q"], capsys, monkeypatch, tmp_path)
    assert code == 0, err
    code, _, err = run_main(["run", "pick-place", "--robot", str(tmp_path / "p.yaml"), "--episodes", "2", "--json",
                             str(tmp_path / "r.json"), "-q"], capsys, monkeypatch, tmp_path)
    assert code == 0, err
    import json

    assert json.loads((tmp_path / "r.json").read_text())["summary"]["success_rate"] == 1.0


def test_drafted_gripper_drive_is_capped_at_the_urdf_speed_so_damped_jaws_move(tmp_path):
    """A jaw joint with ``<dynamics damping>`` (the Unitree Z1's: 1 N·m·s/rad) stalled part-way
    under PyBullet's position drive, which asks for (stiffness / timestep) × error of speed: the
    draft caps the drive at the URDF velocity limit, and the jaw closes and reopens fully."""
    from robocfg.sim.world import World

    text = (ROOT / "tests" / "data" / "sim_onejaw.urdf").read_text()
    limit = '<limit lower="0.0" upper="0.08" effort="40" velocity="0.2"/>'
    assert limit in text
    urdf = tmp_path / "damped_jaw.urdf"
    urdf.write_text(text.replace(limit, limit + '<dynamics damping="100.0" friction="1.0"/>'))
    d = draft_robot(parse_urdf(urdf), "damped", tmp_path)
    assert d.gripper is not None and d.gripper.max_velocity == pytest.approx(0.2)
    out = tmp_path / "damped.yaml"
    out.write_text(render_yaml(d))
    with World(make_task(tmp_path, out)) as w:
        g = w.robot.arm().gripper
        g.close()
        w.step(round(1.0 / w.dt))
        closed = g.fraction()
        g.open()
        w.step(round(1.0 / w.dt))
        assert closed < 0.05 and g.fraction() > 0.95
