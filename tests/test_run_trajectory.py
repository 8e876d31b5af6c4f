"""``robocfg run trajectory`` end to end: the default task tracks in PyBullet; bad input is located."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _cli import run_main

ROOT = Path(__file__).resolve().parent.parent
HEADER = "schema_version: 1\ntask: trajectory\nrobots:\n  - robot: panda\ntrajectory:\n"


def task_file(tmp_path: Path, body: str, name: str = "t.yaml") -> Path:
    f = tmp_path / name
    f.write_text(HEADER + body)
    return f


def test_default_task_plans_checks_and_tracks(tmp_path, capsys, monkeypatch):
    out_json, png = tmp_path / "r.json", tmp_path / "r.png"
    code, out, err = run_main(["run", "trajectory", "--json", str(out_json), "--plot", str(png), "-q"], capsys, monkeypatch)
    assert code == 0, err
    assert out.startswith("ok:") and "Traceback" not in err
    r = json.loads(out_json.read_text())
    assert r["success"] and r["limit_check"]["total"] == 0
    assert r["tracking"]["rms"] <= 0.005 and r["tracking"]["final"] <= 0.002
    assert len(r["waypoints"]) == 3 and r["waypoint_kinds"] == ["home", "pose", "home"]
    s = r["samples"]
    t, q, qd = np.array(s["t"]), np.array(s["q"]), np.array(s["qd"])
    assert t[-1] == pytest.approx(r["duration"]) and np.allclose(np.diff(t)[:-1], 1 / 240)
    assert np.allclose(q[0], r["waypoints"][0]) and np.allclose(q[-1], r["waypoints"][-1])
    assert np.all(np.abs(qd) <= np.array(r["limits"]["velocity"]) * (1 + 1e-6))
    meas = np.array(r["measured"]["q"])
    assert np.allclose(meas[-1], r["waypoints"][-1], atol=0.002)  # the simulated arm really got there
    assert np.max(np.abs(meas[len(meas) // 2] - meas[0])) > 0.3  # ... and really moved
    assert png.stat().st_size > 20_000


def test_waypoint_outside_limits_names_index_and_joint(tmp_path, capsys, monkeypatch):
    f = task_file(tmp_path, "  waypoints:\n    - home\n    - {panda_joint4: 0.5}\n    - [0.0, 0.0, 0.0, -1.0, 0.0, 5.0, 0.0]\n")
    code, _, err = run_main(["run", "trajectory", str(f)], capsys, monkeypatch)
    assert code == 2 and "Traceback" not in err
    assert f"{f}:8:" in err and "waypoints[1].panda_joint4" in err and "waypoint 1: panda_joint4 = 0.5000 is outside" in err
    assert f"{f}:9:" in err and "waypoints[2][5]" in err and "panda_joint6" in err


def test_unknown_names_and_wrong_lengths_are_config_errors(tmp_path, capsys, monkeypatch):
    f = task_file(tmp_path, "  waypoints: [hom, {panda_joint9: 0.1}, [0.1, 0.2]]\n")
    code, _, err = run_main(["run", "trajectory", str(f)], capsys, monkeypatch)
    assert code == 2
    assert "did you mean 'home'" in err and "did you mean 'panda_joint7'" in err and "2 values for 7 arm joints" in err


def test_repeated_waypoints_are_dropped_with_a_warning(tmp_path, capsys, monkeypatch):
    f = task_file(tmp_path, "  waypoints: [home, home, [0.3, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8], home]\n")
    out_json = tmp_path / "r.json"
    code, _, err = run_main(["run", "trajectory", str(f), "--no-sim", "-q", "--json", str(out_json)], capsys, monkeypatch)
    assert code == 0
    r = json.loads(out_json.read_text())
    assert r["waypoint_indices"] == [0, 2, 3]
    assert any("waypoint 1 repeats waypoint 0" in w for w in r["warnings"]) and "repeats" in err


@pytest.mark.parametrize("limits", ["{velocity_scale: 0.0}", "{acceleration: -2.0}", "{jerk: 0}"])
def test_zero_or_negative_limits_are_config_errors(tmp_path, capsys, monkeypatch, limits):
    f = task_file(tmp_path, f"  limits: {limits}\n")
    code, _, err = run_main(["run", "trajectory", str(f), "--no-sim"], capsys, monkeypatch)
    assert code == 2 and "trajectory.limits" in err


def test_zero_velocity_override_in_robot_yaml_is_a_config_error(tmp_path, capsys, monkeypatch):
    panda = (ROOT / "robocfg/data/robots/panda.yaml").read_text()
    (tmp_path / "slow.yaml").write_text(panda.replace("drives:\n", "drives:\n  velocity_limits: {panda_joint2: 0.0}\n"))
    f = tmp_path / "t.yaml"
    f.write_text(HEADER.replace("robot: panda", "robot_config_file: slow.yaml") + "  stop_at_waypoints: false\n")
    code, _, err = run_main(["run", "trajectory", str(f), "--no-sim"], capsys, monkeypatch)
    assert code == 2 and "velocity_limits" in err


def test_cartesian_waypoints_use_ik_with_continuity(tmp_path):
    from robocfg.checks import load_task
    from robocfg.geometry import pose_matrix
    from robocfg.kinematics.model import KinematicModel
    from robocfg.runners.trajectory import plan_task

    poses = ["{position: [0.5, 0.1, 0.3], euler_deg: [180, 0, 0]}",
             "{position: [0.45, -0.1, 0.3], euler_deg: [180, 0, 30]}"]
    f = task_file(tmp_path, "  waypoints:\n    - home\n" + "".join(f"    - {p}\n" for p in poses) + "    - home\n")
    task = load_task(f)
    _, arm, _names, limits, wps, plan = plan_task(task)
    assert wps.kinds == ["home", "pose", "pose", "home"]
    model = KinematicModel.from_robot(task.robots[0], arm.name)
    for i in (1, 2):
        target = pose_matrix(task.config.trajectory.waypoints[i])
        T = model.fk(wps.q[i], "tcp")
        assert np.linalg.norm(T[:3, 3] - target[:3, 3]) < 1e-3
        assert np.allclose(T[:3, :3], target[:3, :3], atol=1e-2)
    # continuity: the second pose is solved from the first, so the joints move little between them
    assert np.max(np.abs(wps.q[2] - wps.q[1])) < 1.0
    assert plan.duration > 0 and np.all(wps.q >= limits.lower) and np.all(wps.q <= limits.upper)


def test_unreachable_cartesian_waypoint_fails_naming_it(tmp_path, capsys, monkeypatch):
    f = task_file(tmp_path, "  waypoints:\n    - home\n    - {position: [0.5, 0.1, 0.3], euler_deg: [180, 0, 0]}\n"
                            "    - {position: [1.5, 0.0, 0.3], euler_deg: [180, 0, 0]}\n")
    code, _, err = run_main(["run", "trajectory", str(f)], capsys, monkeypatch)
    assert code == 1 and "Traceback" not in err
    assert "waypoint 2" in err and "unreachable" in err


def test_stop_at_waypoints_and_jerk_limits_run(tmp_path, capsys, monkeypatch):
    wps = "  waypoints: [home, [0.3, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8], [0.6, -0.2, 0.2, -1.8, 0.0, 1.8, 0.8]]\n"
    for extra, method in (("  stop_at_waypoints: true\n", "trapezoid"), ("  limits: {jerk: 200.0}\n", "ruckig")):
        f = task_file(tmp_path, wps + extra)
        out_json = tmp_path / "r.json"
        code, _, err = run_main(["run", "trajectory", str(f), "-q", "--json", str(out_json)], capsys, monkeypatch)
        assert code == 0, err
        r = json.loads(out_json.read_text())
        assert r["method"] == method and r["limit_check"]["total"] == 0
        assert r["tracking"]["rms"] <= 0.005 and r["tracking"]["final"] <= 0.002


def test_wrong_task_kind_is_rejected(capsys, monkeypatch):
    code, _, err = run_main(["run", "trajectory", "gripper"], capsys, monkeypatch)
    assert code == 2 and "task: trajectory" in err


def test_unreachable_waypoint_fails_with_a_report_naming_the_phase(tmp_path, capsys, monkeypatch):
    """Planning fails before any simulation: exit 1, and --json still holds a report saying why
    (an older file at that path would otherwise look like this run's result)."""
    out = tmp_path / "r.json"
    out.write_text('{"stale": true}')
    far = "trajectory.waypoints=[home, {position: [2.0, 0.0, 0.4], euler_deg: [180, 0, 0]}, home]"
    code, stdout, stderr = run_main(["run", "trajectory", "trajectory", "--set", far, "--json", str(out)],
                                    capsys, monkeypatch)
    assert code == 1
    assert "unreachable" in stdout + stderr
    report = json.loads(out.read_text())
    assert report["success"] is False and report["kind"] == "trajectory" and report["robot"] == "panda"
    assert report["phase"] == "waypoints" and "unreachable" in report["reason"]
    assert report["schema_version"] >= 2


def test_cartesian_waypoint_ik_does_not_depend_on_machine_load(tmp_path, monkeypatch):
    """The waypoints' IK is bounded by iterations, not by the wall clock: with a clock that jumps a
    second per reading (a heavily loaded machine) the plan is the same."""
    from robocfg.checks.task import load_task
    from robocfg.kinematics.ik.lm import LMSolver
    from robocfg.runners.trajectory import plan_task

    task = load_task(ROOT / "robocfg" / "data" / "tasks" / "trajectory.yaml")
    quiet = plan_task(task)[-1].waypoints
    ticks = iter(range(1, 10**9))
    monkeypatch.setattr(LMSolver, "clock", staticmethod(lambda: float(next(ticks))))
    loaded = plan_task(task)[-1].waypoints
    assert np.array_equal(quiet, loaded)
