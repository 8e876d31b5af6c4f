"""``robocfg run follow-target``: short runs in PyBullet (runner result and CLI exit codes / JSON)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
import yaml

from robocfg.checks import load_task
from robocfg.errors import ConfigError, RunFailed
from robocfg.runners.follow_target import run_follow_target

ROOT = Path(__file__).resolve().parent.parent


def _task(tmp_path: Path, follow: dict, name: str = "ft.yaml") -> Path:
    doc = {"schema_version": 1, "task": "follow_target",
           "robots": [{"robot_config_file": str(ROOT / "robocfg" / "data" / "robots" / "panda.yaml")}],
           "scene": {"ground": True}, "sim": {"timestep": 1 / 240}, "follow_target": follow}
    path = tmp_path / name
    path.write_text(yaml.safe_dump(doc))
    return path


def test_static_target_reached_within_1mm(tmp_path):
    follow = {"motion": {"type": "static", "center": [0.5, 0.15, 0.35]}, "duration": 1.5, "settle_time": 1.0}
    res = run_follow_target(load_task(_task(tmp_path, follow)))
    assert res.success and res.reached and res.motion == "static"
    assert res.final_position_error_mm < 1.0 and res.final_orientation_error_deg < 0.57  # 0.01 rad
    assert res.steps == 360 and res.fallback_steps == 0
    assert res.samples[0][1] > 100  # it really started far away (mm)
    assert res.min_clearance_mm is None and res.contacts == 0


def test_obstacle_on_the_path_no_contact_and_margin_kept(tmp_path):
    follow = {"motion": {"type": "static", "center": [0.5, 0.3, 0.3]}, "duration": 2.5, "with_obstacle": True,
              "obstacles": [{"name": "ball", "shape": "sphere", "size": [0.04], "position": [0.4035, 0.15, 0.3935]}]}
    res = run_follow_target(load_task(_task(tmp_path, follow)))
    assert res.obstacles == ["ball"]
    assert res.contacts == 0 and res.contact_steps == 0
    assert res.min_clearance_mm >= res.safety_margin * 1000 - 5.0
    assert res.min_clearance_mm < 40.0  # the obstacle really was in the way
    assert res.reached


def test_moving_obstacle_pushes_the_arm_away_keeping_the_margin(tmp_path):
    # a ball flies onto the (static) target: the TCP must give way, never touching it
    ball = {"name": "drone", "shape": "sphere", "size": [0.04],
            "motion": {"type": "waypoints", "waypoints": [[0.45, 0.3, 0.35], [0.45, 0.03, 0.35]], "waypoint_times": [0.3, 2.0]}}
    follow = {"motion": {"type": "static", "center": [0.45, 0.0, 0.35]}, "duration": 2.2, "with_obstacle": True,
              "obstacles": [ball]}
    res = run_follow_target(load_task(_task(tmp_path, follow)))
    assert res.contacts == 0
    assert res.min_clearance_mm >= res.safety_margin * 1000 - 5.0
    assert res.final_position_error_mm > 30.0  # it gave way: the ball now sits where the target is
    assert res.blocked_time > 0 and not res.reached


def test_target_under_the_table_top_is_held_at_the_margin(tmp_path):
    path = _task(tmp_path, {"motion": {"type": "static", "center": [0.55, 0.1, 0.15]}, "duration": 2.0})
    doc = yaml.safe_load(path.read_text())
    doc["scene"]["table"] = {"position": [0.6, 0.0, 0.2], "size": [0.5, 0.8, 0.04]}
    path.write_text(yaml.safe_dump(doc))
    res = run_follow_target(load_task(path))
    assert res.environment_contact_steps == 0
    assert not res.reached and "blocked" in res.unreachable_reason
    assert res.escapes == 0  # no detour can reach a target inside the table: no thrashing
    tail = [s[1] for s in res.samples if s[0] > 1.5]
    assert max(tail) - min(tail) < 1.0  # mm: held still
    assert 50 < res.final_position_error_mm < 120  # hovering just above the table top


def test_without_obstacle_flag_overrides_the_task(tmp_path):
    follow = {"motion": {"type": "static", "center": [0.45, 0.0, 0.4]}, "duration": 0.3, "with_obstacle": True,
              "obstacles": [{"name": "ball", "shape": "sphere", "size": [0.03], "position": [0.4, 0.3, 0.3]}]}
    res = run_follow_target(load_task(_task(tmp_path, follow)), with_obstacle=False)
    assert res.obstacles == [] and not res.with_obstacle


def test_obstacle_overlapping_the_robot_at_start_is_a_warning(tmp_path):
    # the Panda's home TCP is at (0.307, 0, 0.487): put a box around the hand
    follow = {"motion": {"type": "static", "center": [0.45, 0.0, 0.35]}, "duration": 0.5, "with_obstacle": True,
              "obstacles": [{"name": "crate", "shape": "box", "size": [0.06, 0.06, 0.06], "position": [0.307, 0.0, 0.56]}]}
    res = run_follow_target(load_task(_task(tmp_path, follow)))
    assert any("crate" in w and "overlaps" in w for w in res.warnings)
    assert res.min_clearance_mm < 0  # it really did overlap


def test_unreachable_target_reported_with_residual(tmp_path):
    follow = {"motion": {"type": "static", "center": [1.4, 0.0, 0.4]}, "duration": 1.0}
    res = run_follow_target(load_task(_task(tmp_path, follow)))
    assert res.success and not res.reached  # not required: the run itself succeeds
    assert res.final_position_error_mm > 400
    assert any("not reached" in w and "residual" in w for w in res.warnings)
    follow["require_reach"] = True
    with pytest.raises(RunFailed) as info:
        run_follow_target(load_task(_task(tmp_path, follow, "req.yaml")))
    assert info.value.phase == "track" and info.value.report.final_position_error_mm > 400


def test_unknown_motion_type_is_a_config_error(tmp_path):
    path = _task(tmp_path, {"motion": {"type": "spiral"}})
    with pytest.raises(ConfigError) as info:
        load_task(path)
    text = str(info.value)
    assert "motion.type" in text and "figure8" in text and "circle" in text


def _cli(monkeypatch, capsys, *args) -> tuple[int, str, str]:
    """Run ``robocfg run follow-target ARGS`` in-process through the real entry point."""
    from robocfg.cli.app import main

    monkeypatch.setattr(sys, "argv", ["robocfg", "run", "follow-target", *args])
    with pytest.raises(SystemExit) as info:
        main()
    out = capsys.readouterr()
    return info.value.code, out.out, out.err


def test_cli_json_plot_and_exit_codes(tmp_path, monkeypatch, capsys):
    follow = {"motion": {"type": "circle", "center": [0.4, 0.0, 0.45], "radius": 0.05, "period": 2.0},
              "duration": 1.5, "settle_time": 1.0}
    out, plot = tmp_path / "r.json", tmp_path / "r.png"
    code, stdout, stderr = _cli(monkeypatch, capsys, str(_task(tmp_path, follow)), "--json", str(out), "--plot", str(plot), "-q")
    assert code == 0, stderr
    data = json.loads(out.read_text())
    assert data["motion"] == "circle" and data["position_error_mm"]["rms"] < 5.0
    assert plot.stat().st_size > 1000 and stdout.startswith("ok:")
    code, _, stderr = _cli(monkeypatch, capsys, str(_task(tmp_path, {"motion": {"type": "spiral"}}, "bad.yaml")))
    assert code == 2 and "static" in stderr and "Traceback" not in stderr
    req = _task(tmp_path, {"motion": {"type": "static", "center": [1.4, 0, 0.4]}, "duration": 0.5, "require_reach": True}, "req.yaml")
    code, stdout, stderr = _cli(monkeypatch, capsys, str(req), "--json", str(out), "-q")
    assert code == 1 and stdout.startswith("failed: track: ") and "residual" in stdout  # the -q result line
    assert "failed: track" not in stderr  # printed once
    assert json.loads(out.read_text())["reached"] is False  # the report is written even on failure
