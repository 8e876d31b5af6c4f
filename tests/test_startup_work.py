"""Work a process does once before its first episode, not again: a behaviour check of the start-up
(benchmarks/bench_startup.py measures its time; no wall-clock assert here)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import robocfg.assets.fingers as fingers
from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session

ROOT = Path(__file__).resolve().parents[1]


def test_a_valid_task_is_validated_without_building_every_kinds_validator() -> None:
    """The task's own kind validates it (the member the union would pick); the union of every kind
    is built only to report an invalid document."""
    code = ("import robocfg.checks.task as t; from robocfg.config import catalog\n"
            "t.load_task(catalog.find('tasks', 'pick_place')); assert t._TASK_ADAPTER is None, 'union built'\n"
            "from robocfg.config.load import load_yaml\n"
            "doc = load_yaml(catalog.find('tasks', 'pick_place')); doc.data['pick_place']['lift_hieght'] = 0.1\n"
            "from robocfg.errors import ConfigError\n"
            "try:\n    t.check_task_document(doc)\nexcept ConfigError as e:\n    print(e.problems[0].message)\n"
            "assert t._TASK_ADAPTER is not None")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "unknown key 'lift_hieght'" in out.stdout and "did you mean 'lift_height'" in out.stdout


def test_the_pad_gap_curve_is_computed_once_per_process(monkeypatch: pytest.MonkeyPatch) -> None:
    """The task check, the gripper and the pick-place session all ask for it; one FK sweep."""
    calls = []
    real = fingers.width_curve

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(fingers, "width_curve", counted)
    task = load_task(catalog.find("tasks", "pick_place"))
    s = open_session(task, RunOptions(seed=0))
    try:
        assert s.tools.pad_force is not None and s.handle.gripper is not None
        assert len(calls) == 1
        s2 = s.task.robots[0].pad_gap_curve(s.arm_cfg)
        assert s2 is not None and not s2[1].flags.writeable  # shared, so nobody may change it
    finally:
        s.close()


@pytest.mark.parametrize("robot", sorted((ROOT / "robocfg" / "data" / "robots").glob("*.yaml")), ids=lambda r: r.stem)
def test_pad_gap_curve_with_the_chain_memo_is_bit_identical(robot: Path) -> None:
    """``width_curve`` keeps Urdf.link_pose's chain products over its sweep: the same gaps, bit
    for bit, as every pose computed from the root (the gripper's width commands depend on them)."""
    import numpy as np

    from robocfg.assets.fingers import closing_axis, finger_points, pad_gap, pad_points, width_curve
    from robocfg.assets.paths import Resolver
    from robocfg.checks.robot import load_robot
    from robocfg.config.robot import ParallelGripperConfig
    from robocfg.config.types import AXIS_INDEX

    checked = load_robot(robot)
    arms = [a for a in checked.config.arms if isinstance(a.gripper, ParallelGripperConfig)]
    if not arms:
        pytest.skip("no parallel gripper")
    for arm in arms:
        g = arm.gripper
        assert isinstance(g, ParallelGripperConfig)
        resolver = Resolver(checked.path.parent, checked.config.package_dirs)
        args = (checked.urdf, resolver, arm.ee_link, AXIS_INDEX[arm.ee_axis], list(g.finger_links),
                checked.gripper_joints(arm), g.open, g.closed, closing_axis(arm.R_ee_graspnet))
        s, gaps = width_curve(*args)
        points = finger_points(checked.urdf, resolver, list(g.finger_links))
        qo, qc = np.asarray(g.open, float), np.asarray(g.closed, float)
        leaders = checked.gripper_joints(arm)
        plain = np.array([pad_gap(pad_points(checked.urdf, arm.ee_link, list(g.finger_links), points,
                                             dict(zip(leaders, qc + k * (qo - qc), strict=True)), AXIS_INDEX[arm.ee_axis]),
                                  closing_axis(arm.R_ee_graspnet)) for k in s])
        assert gaps.tobytes() == plain.tobytes() and np.ptp(gaps) > 0


def test_a_pick_place_process_to_its_first_episode_parses_no_builtin_signature() -> None:
    """pydantic reads each ``default_factory``'s signature; a builtin's (``list``) is parsed with
    ``tokenize``, whose first use compiles its regular expressions. The config models' list
    fields use ``robocfg.config.types.new_list``, so a process validating its task and running
    its first episode never does."""
    code = ("import tokenize\n"
            "from robocfg.checks.task import load_task; from robocfg.config import catalog\n"
            "from robocfg.engine import RunOptions, open_session\n"
            "s = open_session(load_task(catalog.find('tasks', 'pick_place')), RunOptions(seed=0))\n"
            "assert s.run(0).success; s.close()\n"
            "assert tokenize._compile.cache_info().currsize == 0, 'tokenize compiled'")
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]


def test_config_list_fields_default_to_a_new_empty_list() -> None:
    from robocfg.config.scene import Scene
    from robocfg.config.types import new_list

    a, b = Scene(), Scene()
    assert a.objects == [] and a.objects is not b.objects  # a new list each time, as `list` gave
    assert Scene.model_fields["objects"].default_factory is new_list
