"""``robocfg ik`` and ``robocfg bench ik``: exit codes, printed residuals, JSON reports."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from _cli import run_main

ROOT = Path(__file__).parents[1]


def test_ik_converges_and_fk_matches(tmp_path, capsys, monkeypatch) -> None:
    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.kinematics.model import KinematicModel

    report = tmp_path / "ik.json"
    code, out, _ = run_main(["ik", "panda", "--position", "0.5", "0.1", "0.3", "--euler-deg", "180", "0", "0",
                             "--json", str(report)], capsys, monkeypatch)
    assert code == 0, out
    assert "converged" in out and "panda_joint1" in out
    data = json.loads(report.read_text())
    model = KinematicModel.from_robot(load_robot(catalog.find("robots", "panda")))
    T = model.fk(np.array(list(data["joints"].values())), "tcp")
    np.testing.assert_allclose(T[:3, 3], [0.5, 0.1, 0.3], atol=1e-5)
    np.testing.assert_allclose(T[:3, 2], [0, 0, -1], atol=1e-5)  # roll 180°: tool z points down


def test_ik_quaternion_and_seed(capsys, monkeypatch) -> None:
    code, out, _ = run_main(["ik", "panda", "--position", "0.4", "0", "0.5", "--quat-xyzw", "1", "0", "0", "0",
                             "--frame", "ee", "--seed-q", "0,-0.7,0,-2.3,0,1.6,0.8", "-q"], capsys, monkeypatch)
    assert code == 0, out


def test_ik_unreachable_exits_1(capsys, monkeypatch) -> None:
    code, out, err = run_main(["ik", "panda", "--position", "3", "0", "0.5", "--euler-deg", "0", "0", "0",
                               "--budget-ms", "10"], capsys, monkeypatch)
    assert code == 1
    assert "NOT converged" in out and "ik: did not converge" in err


@pytest.mark.parametrize("args", [
    ["--position", "0.4", "0", "nan", "--euler-deg", "0", "0", "0"],
    ["--position", "0.4", "0", "0.4", "--euler-deg", "0", "0", "0", "--quat-xyzw", "0", "0", "0", "1"],
    ["--position", "0.4", "0", "0.4", "--quat-xyzw", "0", "0", "0", "2"],
    ["--position", "0.4", "0", "0.4", "--backend", "nope"],
])
def test_ik_bad_input_exits_2(args, capsys, monkeypatch) -> None:
    code, _, err = run_main(["ik", "panda", *args], capsys, monkeypatch)
    assert code == 2, err
    assert "Traceback" not in err


def test_bench_ik_writes_rows(tmp_path, capsys, monkeypatch) -> None:
    report = tmp_path / "bench.json"
    # The protocol's 5 ms wall budget is a speed measurement: on a loaded machine (CI at load 11)
    # LM's p95 passes it and 2 of 5 queries fail. Here the rows and their success are checked with
    # a budget ~40x LM's p95, on this thread's CPU clock, so load cannot decide the outcome.
    code, out, _ = run_main(["bench", "ik", "--robot", "panda", "-n", "5", "--backends", "lm",
                             "--budget-ms", "200", "--budget-clock", "cpu",
                             "--json", str(report)], capsys, monkeypatch)
    assert code == 0, out
    data = json.loads(report.read_text())
    assert [r["backend"] for r in data["rows"]] == ["lm", "pybullet"]
    assert all(r["n"] == 5 for r in data["rows"])
    assert data["rows"][0]["success_pct"] >= 80.0
