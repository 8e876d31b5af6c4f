"""Pick and place on real physics: the cube really ends on the place point, held by friction."""

import json
import subprocess
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine.options import EpisodeObserver
from robocfg.errors import ConfigError
from robocfg.runners.pick_place import episode_setups, run_pick_place


@pytest.fixture(scope="module")
def task():
    return load_task(catalog.find("tasks", "pick_place"))


@pytest.fixture(scope="module")
def two_episodes(task):
    return run_pick_place(task, episodes=2, seed=7)[0]


def test_default_task_places_the_cube(two_episodes, task):
    params = task.config.pick_place
    for e in two_episodes.episodes:
        assert e.success, (e.failed_phase, e.reason)
        final = np.array(e.object_final)
        assert np.linalg.norm(final[:2] - np.array(e.place_target)) <= params.success_tolerance
        assert abs(final[2] - params.object.size[2] / 2) < 0.01  # resting on the ground
        assert e.tilt_deg <= params.max_tilt_deg
        assert e.lift_rise > 0.5 * params.lift_height  # it really rose with the fingers
        assert [p.name for p in e.phases] == ["pre_grasp", "approach", "grasp", "lift", "transport",
                                              "lower", "release", "retract"]
        assert e.sim_time <= 8.0
        start = np.array(e.object_start[:2])
        assert np.linalg.norm(final[:2] - start) > 0.2  # it moved


def test_same_seed_same_report(task, two_episodes):
    again = run_pick_place(task, episodes=2, seed=7)[0]
    assert json.dumps(asdict(again), sort_keys=True) == json.dumps(asdict(two_episodes), sort_keys=True)


def test_episode_setups_follow_the_seed(task):
    params = task.config.pick_place
    a, b = episode_setups(params, 3, 5), episode_setups(params, 3, 5)
    assert [s.body.position for s in a] == [s.body.position for s in b]
    c = episode_setups(params, 4, 5)
    assert [s.body.position for s in a] != [s.body.position for s in c]
    rng = params.randomize.object
    for s in a:
        assert abs(s.body.position[0] - params.object.position[0]) <= rng.xy_range[0]
        assert abs(np.degrees(s.yaw)) <= rng.yaw_range_deg + 1e-9


def _variant(tmp_path: Path, edit) -> Path:
    src = catalog.find("tasks", "pick_place")
    data = yaml.safe_load(src.read_text())
    edit(data)
    out = tmp_path / "task.yaml"
    out.write_text(yaml.safe_dump(data))
    return out


def test_object_out_of_reach_fails_in_pre_grasp(tmp_path):
    def far(d):
        d["pick_place"]["object"]["position"] = [1.6, 0.0, 0.025]
        d["pick_place"]["randomize"]["object"] = {"xy_range": [0.0, 0.0], "yaw_range_deg": 0.0}
    report, _ = run_pick_place(load_task(_variant(tmp_path, far)))
    e = report.episodes[0]
    assert not e.success and e.failed_phase == "pre_grasp" and "unreachable" in e.reason


def test_object_wider_than_gripper_is_a_config_error(tmp_path):
    def wide(d):
        d["pick_place"]["object"]["size"] = [0.12, 0.12, 0.05]
    with pytest.raises(ConfigError) as exc:
        load_task(_variant(tmp_path, wide))
    assert any("max_width" in p.message for p in exc.value.problems)


def test_cli_quiet_json(tmp_path):
    out = tmp_path / "r.json"
    proc = subprocess.run([sys.executable, "-m", "robocfg", "run", "pick-place", "-q", "--json", str(out)],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "placed 1/1" in proc.stdout
    report = json.loads(out.read_text())
    assert report["summary"]["success_rate"] == 1.0
    assert "Traceback" not in proc.stderr


class _ConstraintSpy(EpisodeObserver):
    """Stands in for a Recorder: after every step, looks for any constraint touching the object."""

    def __init__(self, world):
        self.world, self.checked, self.offending = world, 0, []

    def maybe_capture(self):
        import pybullet as p

        c = self.world.client
        obj = self.world.bodies.get("cube")
        for k in range(p.getNumConstraints(physicsClientId=c)):
            info = p.getConstraintInfo(p.getConstraintUniqueId(k, physicsClientId=c), physicsClientId=c)
            if obj in (info[0], info[2]):
                self.offending.append(info)
        self.checked += 1

    def save(self):
        pass


def test_cube_is_held_by_friction_only(task):
    spies = []

    def factory(world):
        spies.append(_ConstraintSpy(world))
        return spies[-1]

    report, _ = run_pick_place(task, episodes=1, seed=1, record=factory)
    assert report.episodes[0].success
    assert spies[0].checked > 500 and spies[0].offending == []


@pytest.mark.parametrize(("xy", "z", "dropped"), [
    ((0.500, 0.200), 0.0249, False),  # resting on the floor at the place point, pressed 0.1 mm into it
    ((0.505, 0.200), 0.0265, False),  # 1.5 mm above resting, 5 mm from the point: set down
    ((0.500, 0.200), 0.0400, True),   # 15 mm up: it fell out of the hand on the way down
    ((0.550, 0.200), 0.0250, True),   # resting, but 5 cm from the place point
])
def test_lowering_counts_an_object_already_set_down_at_the_place_point_as_placed(xy, z, dropped):
    """A one-jaw gripper's fixed jaw can leave the object as the floor takes its weight a moment
    before the lower ends; that is a set-down, not a drop, when the object rests at the place point."""
    from types import SimpleNamespace

    from robocfg.runners.pick_place_machine import _StateMachine

    cube = SimpleNamespace(below_origin=lambda R: 0.025)
    sm = SimpleNamespace(
        _dropped=lambda: "object dropped (2.0 cm from the TCP)", obj=7, shape=cube,
        world=SimpleNamespace(body_pose=lambda body: (np.array([*xy, z]), np.array([0.0, 0.0, 0.0, 1.0]))),
        setup=SimpleNamespace(place_xy=np.array([0.5, 0.2])), params=SimpleNamespace(success_tolerance=0.02),
        _support_height=lambda xy: 0.0)
    why = _StateMachine._dropped_before_placed(sm)  # type: ignore[arg-type]
    assert (why is not None) == dropped
