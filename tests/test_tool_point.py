"""Working points against geometry: suction TCP = cup face, one-jaw fixed_jaw_face, and the
likely cause a failed grasp names (tcp_offset against the measured pads)."""

from __future__ import annotations

from pathlib import Path

from robocfg.assets.paths import Resolver
from robocfg.checks import load_robot
from robocfg.checks.tool_point import cup_face, grasp_failure_hint

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"


def _variant(tmp_path: Path, src: Path, old: str, new: str) -> Path:
    text = src.read_text()
    assert old in text
    tmp_path.mkdir(parents=True, exist_ok=True)
    out = tmp_path / src.name
    out.write_text(text.replace(old, new))
    for f in src.parent.glob("*.urdf"):
        (tmp_path / f.name).write_text(f.read_text())
    return out


def test_suction_tcp_is_checked_against_the_cup_face(tmp_path):
    robot = load_robot(DATA / "sim_suction_robot.yaml")
    arm = robot.config.arms[0]
    assert abs(cup_face(robot.urdf, Resolver(robot.path.parent), arm, arm.gripper) - 0.03) < 1e-9
    assert robot.warnings == []
    past = load_robot(_variant(tmp_path, DATA / "sim_suction_robot.yaml", "tcp_offset: 0.03", "tcp_offset: 0.13"))
    [w] = past.warnings
    assert w.path == "arms[0].tcp_offset" and "cup face, measured at 0.0300 m" in w.message


def test_one_jaw_face_off_the_geometry_warns(tmp_path):
    assert load_robot(DATA / "sim_onejaw_robot.yaml").warnings == []
    off = load_robot(_variant(tmp_path, DATA / "sim_onejaw_robot.yaml", "fixed_jaw_face: 0.02", "fixed_jaw_face: -0.02"))
    [w] = off.warnings
    assert w.path == "arms[0].gripper.fixed_jaw_face" and "measured at 0.0200 m" in w.message


def test_failed_grasp_names_tcp_offset_against_the_closed_pads(tmp_path):
    shipped = ROOT / "robocfg" / "data" / "robots" / "ur5e_robotiq_2f85.yaml"
    text = shipped.read_text().replace("tcp_offset: 0.144\n", "tcp_offset: 0.1303\n")
    (tmp_path / "ur5e.yaml").write_text(text)
    robot = load_robot(tmp_path / "ur5e.yaml")
    arm = robot.config.arms[0]
    hint = grasp_failure_hint(robot.urdf, Resolver(robot.path.parent), arm, ["finger_joint"], 0.0687)
    assert hint == "object slipped: check tcp_offset (now 0.130 m, pads measured at 0.144 m closed, 0.130 m open)"
    assert grasp_failure_hint(robot.urdf, Resolver(robot.path.parent), arm, ["finger_joint"], 0.0).startswith(
        "fingers closed on nothing: check tcp_offset")
    good = load_robot(shipped)
    hint = grasp_failure_hint(good.urdf, Resolver(good.path.parent), good.config.arms[0], ["finger_joint"], 0.05)
    assert "tcp_offset" not in hint and "max_force 1" in hint


def test_links_without_inertial_load_light_not_as_1_kg(tmp_path):
    """tool0 (a bare frame under a fixed joint) has no <inertial>: validate warns and PyBullet gets
    0.001 kg, not its 1 kg default; a link_masses entry wins."""
    import pybullet as p
    import yaml
    from _sim_helpers import make_task

    from robocfg.sim.world import World

    src = DATA / "sim_onejaw_robot.yaml"
    bare = _variant(tmp_path, src, "  link_masses:\n    tool0: 0.001\n", "")
    robot = load_robot(bare)
    [w] = robot.warnings
    assert "'tool0' has no <inertial>" in w.message and "0.001 kg" in w.message
    for path, want in ((bare, 0.001), (_variant(tmp_path / "given", src, "tool0: 0.001", "tool0: 0.25"), 0.25)):
        with World(make_task(tmp_path, path)) as world:
            r = world.robot
            assert p.getDynamicsInfo(r.body_id, r.link("tool0"), physicsClientId=r.client)[0] == want
    assert yaml.safe_load(src.read_text())["physics"]["link_masses"] == {"tool0": 0.001}
