"""``robocfg run gripper``: the runner's typed result and the CLI (exit codes, JSON, pictures)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest
from _sim_helpers import DATA, ROOT, make_task

from robocfg.checks import load_task
from robocfg.errors import RunFailed
from robocfg.runners.gripper import run_gripper

CUBE = {"name": "cube", "shape": "box", "size": [0.04, 0.04, 0.04], "mass": 0.1, "position": [0.6, 0.3, 0.02]}


def test_default_task_closes_opens_and_holds(tmp_path):
    res = run_gripper(load_task(ROOT / "robocfg" / "data" / "tasks" / "gripper.yaml"))
    assert res.success and res.robot == "panda"
    assert res.width_change >= 0.8 * (res.max_width - res.min_width)
    assert res.final_closed_width < 0.003 and res.final_open_width > 0.07
    assert 0 < res.time_to_close < 1.0 and 0 < res.time_to_open < 1.0
    assert res.mimic_max_error <= 0.01
    assert res.hold.held and res.hold.grasping_after and res.hold.released
    assert res.hold.width_on_object == pytest.approx(0.04, abs=0.003)
    widths = [w for _, w in res.samples]
    assert max(widths) - min(widths) > 0.07  # the measured width really moved over time


def test_direct_mode_two_cycles_without_object(tmp_path):
    extra = {"gripper": {"cycles": 2, "mode": "direct", "hold_time": 0.8}}
    res = run_gripper(make_task(tmp_path, ROOT / "robocfg" / "data" / "robots" / "panda.yaml", extra=extra))
    assert res.success and res.hold is None
    assert [m.phase for m in res.moves] == ["close", "open", "close", "open"]


def test_slippery_heavy_object_fails_in_hold_phase(tmp_path):
    heavy = {**CUBE, "mass": 3.0, "friction": 0.05}
    extra = {"gripper": {"hold_object": "cube", "lift_support_by": 0.05, "mode": "direct", "hold_time": 0.4}}
    task = make_task(tmp_path, ROOT / "robocfg" / "data" / "robots" / "panda.yaml", objects=[heavy], extra=extra)
    with pytest.raises(RunFailed) as info:
        run_gripper(task)
    exc = info.value
    assert exc.phase == "hold" and exc.report is not None and not exc.report.success
    assert exc.report.failed_phase == "hold" and exc.report.hold.drop > 0.01


def test_suction_robot_holds_and_releases(tmp_path):
    box = {"name": "box", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.2, "position": [0.4, 0.0, 0.025]}
    extra = {"gripper": {"hold_object": "box", "lift_support_by": 0.1}}
    res = run_gripper(make_task(tmp_path, DATA / "sim_suction_robot.yaml", objects=[box], extra=extra))
    assert res.success and res.gripper_type == "suction"
    assert res.hold.held and res.hold.drop < 0.01 and res.hold.released


def _cli(*args, cwd):
    return subprocess.run([sys.executable, "-c", "from robocfg.cli.app import main; main()", "run", "gripper", *args],
                          capture_output=True, text=True, cwd=cwd, timeout=300)


def test_cli_ok_json_and_png(tmp_path):
    out = _cli("--json", str(tmp_path / "r.json"), "--record", str(tmp_path / "last.png"), cwd=ROOT)
    assert out.returncode == 0, out.stderr
    assert "time to close" in out.stdout and "pybullet build time" not in out.stdout + out.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["success"] and report["hold"]["held"]
    import numpy as np
    from PIL import Image

    img = np.asarray(Image.open(tmp_path / "last.png").convert("RGB"))
    assert img.shape == (240, 320, 3)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 50  # a real picture, not a blank frame


def test_cli_failure_exit_1_with_phase_and_report(tmp_path):
    heavy = {**CUBE, "mass": 3.0, "friction": 0.05}
    extra = {"gripper": {"hold_object": "cube", "mode": "direct", "hold_time": 0.4}}
    make_task(tmp_path, ROOT / "robocfg" / "data" / "robots" / "panda.yaml", objects=[heavy], extra=extra, name="slip.yaml")
    out = _cli(str(tmp_path / "slip.yaml"), "--json", str(tmp_path / "r.json"), "-q", cwd=tmp_path)
    assert out.returncode == 1
    both = out.stdout + out.stderr  # the -q result line names the phase, printed once
    assert both.count("failed: hold:") == 1 and "Traceback" not in out.stderr
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["failed_phase"] == "hold" and not report["success"]


def test_cli_wrong_task_kind_is_invalid_input(tmp_path):
    make_task(tmp_path, ROOT / "robocfg" / "data" / "robots" / "panda.yaml", task="trajectory", name="traj.yaml")
    out = _cli(str(tmp_path / "traj.yaml"), cwd=tmp_path)
    assert out.returncode == 2 and "task: gripper" in out.stderr


def test_robotiq_linkage_moves_as_one_and_holds(tmp_path):
    """airo-models' 2F-85: finger_joint + 5 mimic followers geared; pads 86 → 1.5 mm; a cube held."""
    cube = {**CUBE, "mass": 0.1}
    extra = {"gripper": {"hold_object": "cube", "lift_support_by": 0.1, "mode": "direct", "hold_time": 0.6}}
    mount = {"position": [0.0, 0.0, 0.4], "euler_deg": [180.0, 0.0, 0.0]}
    res = run_gripper(make_task(tmp_path, DATA / "sim_robotiq_2f85_robot.yaml", objects=[cube], mount=mount, extra=extra))
    assert res.success and not [w for w in res.warnings if "mimic" in w]
    assert res.final_open_width == pytest.approx(0.086, abs=0.002)
    assert res.final_closed_width == pytest.approx(0.0015, abs=0.001)
    assert res.mimic_max_error <= 0.01  # while closing freely, grasping and holding
    assert res.hold.held and res.hold.drop < 0.002 and res.hold.width_on_object == pytest.approx(0.04, abs=0.002)
