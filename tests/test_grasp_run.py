"""``run grasp`` end to end on Panda: perceive, plan, lift and shake for real; bad input fails clearly."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.runners.grasp import episode_setups, run_grasp


@pytest.fixture(scope="module")
def task():
    return load_task(catalog.find("tasks", "grasp"))


def _variant(tmp_path: Path, edit) -> Path:
    data = yaml.safe_load(catalog.find("tasks", "grasp").read_text())
    edit(data)
    out = tmp_path / "grasp.yaml"
    out.write_text(yaml.safe_dump(data))
    return out


def test_panda_lifts_the_cube(task, tmp_path):
    saved = []
    report, timing = run_grasp(task, episodes=1, seed=0, save_cloud=saved.append)
    e = report.episodes[0]
    assert e.object == "cube"
    assert e.success, (e.failed_phase, e.reason)
    assert e.lift_rise > 0.5 * task.config.grasp.lift_height  # it really rose, after the shake too
    assert e.candidates >= 1 and e.poses_evaluated > 0 and e.object_points >= 100
    best = e.attempts[0].candidate
    assert best["width"] <= 0.08 and abs(best["width"] - 0.05) < 0.01  # across the 5 cm cube
    assert len(timing.planning) == len(e.attempts) and timing.planning[0] > 0
    cloud = saved[0]
    x, y = e.object_start[:2]
    assert np.all(np.abs(cloud.points[:, :2] - [x, y]) < 0.05)  # the object's cloud is where it was put
    assert np.all(np.linalg.norm(cloud.normals, axis=1) > 0.99)


def test_episode_setups_follow_the_seed(task):
    params = task.config.grasp
    a, b = episode_setups(params, 3, 9), episode_setups(params, 3, 9)
    assert [s.body.position for s in a] == [s.body.position for s in b]
    assert [s.body.name for s in a] == [o.name for o in params.objects]
    for s in a:
        base = next(o for o in params.objects if o.name == s.body.name)
        assert abs(s.body.position[0] - base.position[0]) <= params.randomize.xy_range[0]


def test_too_wide_object_reports_rejections(tmp_path):
    def wide(d):
        d["grasp"]["objects"] = [{"name": "slab", "shape": "box", "size": [0.14, 0.14, 0.04],
                                  "position": [0.5, 0.0, 0.02], "mass": 0.2}]
        d["grasp"]["randomize"] = {"xy_range": [0.0, 0.0], "yaw_range_deg": 0.0}
    report, _ = run_grasp(load_task(_variant(tmp_path, wide)))
    e = report.episodes[0]
    assert not e.success and e.failed_phase == "planning"
    assert "no feasible grasp" in e.reason and "not_antipodal" in e.reason


def test_cli_no_object_points_exits_1(tmp_path):
    def empty_workspace(d):
        d["grasp"]["workspace"] = {"min": [0.3, 0.5, -0.01], "max": [0.7, 0.8, 0.3]}  # beside the object
    path = _variant(tmp_path, empty_workspace)
    out = tmp_path / "r.json"
    proc = subprocess.run([sys.executable, "-m", "robocfg", "run", "grasp", str(path), "-q", "--json", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    report = json.loads(out.read_text())
    assert report["episodes"][0]["failed_phase"] == "perception"
    assert "no object points in the workspace" in report["episodes"][0]["reason"]
    assert any("looks away" in w for w in report["warnings"])  # the camera no longer sees the workspace centre
