"""Continuous joints (no limits, one angle each) in IK, trajectory and follow-target, on the authored
sim_onejaw fixture whose base (j1) and wrist roll (j6) are continuous and whose home has j6 = π."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from _cli import run_main
from _sim_helpers import DATA

from robocfg.checks import load_robot
from robocfg.kinematics.model import KinematicModel

ROBOT = DATA / "sim_onejaw_robot.yaml"


def _task(tmp_path: Path, kind: str, params: dict) -> Path:
    doc = {"schema_version": 1, "task": kind, "robots": [{"robot_config_file": str(ROBOT)}],
           "scene": {"ground": True}, "sim": {"timestep": 1 / 240}, kind: params}
    path = tmp_path / f"{kind}.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return path


def test_ik_answers_match_fk_and_continuous_joints_take_the_nearest_turn():
    model = KinematicModel.from_robot(load_robot(ROBOT))
    assert model.continuous.tolist() == [True, False, False, False, False, True]
    rng = np.random.default_rng(3)
    home = np.array(model.home)
    for _ in range(12):
        q_true = home + rng.uniform(-0.4, 0.4, 6)
        q_true[[0, 5]] = rng.uniform(-math.pi, math.pi, 2)  # continuous joints anywhere on the circle
        target = model.fk(q_true)
        res = model.ik(target, seed_q=home, time_budget=0.5)
        assert res.converged
        T = model.fk(res.q)
        assert np.linalg.norm(T[:3, 3] - target[:3, 3]) < 1e-4
        assert np.allclose(T[:3, :3], target[:3, :3], atol=1e-4)
        assert abs(res.q[5] - home[5]) <= math.pi + 1e-6  # the turn nearest the seed, not wrapped into [-π, π]
    # Seeded at π − 0.05, a target 0.1 rad further on is reached at π + 0.05 (0.1 rad of travel), not at −π + 0.05.
    seed = home.copy()
    seed[5] = math.pi - 0.05
    q_true = seed.copy()
    q_true[5] = -math.pi + 0.05
    res = model.ik(model.fk(q_true), seed_q=seed, time_budget=0.5)
    assert res.converged and res.q[5] == pytest.approx(math.pi + 0.05, abs=1e-3)
    assert model.within_limits(res.q)


def test_trajectory_turns_a_continuous_wrist_past_pi(tmp_path, capsys, monkeypatch):
    task = _task(tmp_path, "trajectory", {
        "waypoints": ["home", {"position": [0.45, 0.3, 0.35], "euler_deg": [180.0, 0.0, -60.0]}, "home"],
        "orientation_frame": "ee_link",  # the angles of the fixture's own ee_link (its wrist turn past π)
        "limits": {"velocity_scale": 0.5, "acceleration_scale": 0.5, "acceleration": 10.0}})
    out = tmp_path / "r.json"
    code, _, err = run_main(["run", "trajectory", str(task), "--json", str(out), "-q"], capsys, monkeypatch)
    assert code == 0, err
    r = json.loads(out.read_text())
    q = np.array(r["measured"]["q"])
    assert r["success"] and r["tracking"]["rms"] <= 0.005
    assert q[:, 5].max() > math.pi + 0.5  # the wrist went on past π ...
    assert q[:, 5].max() < math.pi + 2.5  # ... the short way (≈ 1.7 rad), not round through −π
    assert np.allclose(q[-1], r["waypoints"][-1], atol=0.002)


def test_follow_target_runs_on_continuous_joints(tmp_path, capsys, monkeypatch):
    task = _task(tmp_path, "follow_target", {
        "motion": {"type": "circle", "center": [0.5, 0.0, 0.4], "radius": 0.1, "period": 4.0, "plane": "yz"},
        "target_euler_deg": [180.0, 0.0, 0.0], "orientation_frame": "ee_link", "duration": 3.0, "settle_time": 1.0})
    out = tmp_path / "r.json"
    code, _, err = run_main(["run", "follow-target", str(task), "--json", str(out), "-q"], capsys, monkeypatch)
    assert code == 0, err
    r = json.loads(out.read_text())
    assert r["success"] and r["reached"]
    assert r["position_error_mm"]["rms"] < 3.0 and r["orientation_error_deg"]["max"] < 1.0


def test_controller_urdf_has_one_angle_per_continuous_joint_and_no_name_clash(tmp_path):
    """What the follow-target controller hands placo: continuous joints revolute (one coordinate),
    and a fixed joint named like a link (Unitree Z1's 'gripperStator') renamed."""
    import xml.etree.ElementTree as ET

    from robocfg.motion.reactive.placo_urdf import urdf_without_geometry

    text = (DATA / "sim_onejaw.urdf").read_text().replace('joint name="palm_joint"', 'joint name="palm"')
    (tmp_path / "r.urdf").write_text(text)
    root = ET.fromstring(urdf_without_geometry(tmp_path / "r.urdf"))
    joints = {j.get("name"): j for j in root.iter("joint")}
    assert joints["j1"].get("type") == joints["j6"].get("type") == "revolute"
    assert "palm" not in joints and joints["palm__fixed_joint"].get("type") == "fixed"
    assert not root.findall(".//collision") and not root.findall(".//visual")
