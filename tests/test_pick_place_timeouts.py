"""Phase time limits derive from the planned motion: a slow arm (here the Panda at 12 % of its
joint speed, every move several seconds long) is slow, not failed; a fixed limit still binds."""

import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.motion.moves import TIMEOUT_FACTOR, TIMEOUT_MARGIN, UNPLANNED_TIMEOUT, ArmMover
from robocfg.runners.pick_place import run_pick_place


def _slow_task(tmp_path, timeouts: dict | None = None):
    data = yaml.safe_load(catalog.find("tasks", "pick_place").read_text())
    data["pick_place"]["speed_scale"] = 0.12
    if timeouts:
        data["pick_place"]["timeouts"] = timeouts
    path = tmp_path / "slow.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)


def test_slow_arm_succeeds_with_derived_limits(tmp_path):
    report, _ = run_pick_place(_slow_task(tmp_path), episodes=1, seed=0)
    e = report.episodes[0]
    assert e.success, (e.failed_phase, e.reason)
    pre = next(p for p in e.phases if p.name == "pre_grasp")
    assert pre.t_end - pre.t_start > 4.0  # longer than the old fixed 4 s limit allowed


def test_fixed_limit_still_binds(tmp_path):
    report, _ = run_pick_place(_slow_task(tmp_path, {"pre_grasp": 4.0}), episodes=1, seed=0)
    e = report.episodes[0]
    assert not e.success and e.failed_phase == "pre_grasp"
    assert "more than the 4.00 s timeout" in e.reason


def test_time_limit_rule():
    m = ArmMover.__new__(ArmMover)
    m.timeout = None
    assert m.time_limit(4.6) == pytest.approx(4.6 * TIMEOUT_FACTOR + TIMEOUT_MARGIN)
    assert m.time_limit(2.0, factor=2.0) == pytest.approx(4.0 * TIMEOUT_FACTOR + TIMEOUT_MARGIN)
    assert m.time_limit(None) == UNPLANNED_TIMEOUT
    m.timeout = 3.0
    assert m.time_limit(10.0) == 3.0
