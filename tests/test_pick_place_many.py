"""``run pick-place-many``: several objects, each in its own region, checked before simulating
(place target, capacity, regions into fixtures and into each other), picked with clutter-filtered
grasps and placed on spots that keep them apart; failures name the object and the phase."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.checks.clutter import footprint_radius, place_spots
from robocfg.config import catalog
from robocfg.engine import RunOptions
from robocfg.errors import ConfigError
from robocfg.runners.pick_place_many import PickPlaceManyRunner


@pytest.fixture(scope="module")
def bin_to_bin():
    return load_task(catalog.find("tasks", "pick_place_many"))


def _variant(tmp_path, task, change) -> object:
    """The shipped task's YAML with ``change(data)`` applied, loaded from ``tmp_path``."""
    data = copy.deepcopy(yaml.safe_load(task.path.read_text()))
    data.pop("$schema", None)
    change(data)
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _problems(path) -> list:
    with pytest.raises(ConfigError) as exc:
        load_task(path)
    return exc.value.problems


def test_place_spots_keep_objects_apart_and_inside_the_bin(bin_to_bin):
    params = bin_to_bin.config.pick_place_many
    r = max(footprint_radius(o, bin_to_bin.path.parent) for o in params.objects)
    spots = place_spots(bin_to_bin.config.scene, params.place, r).points
    assert len(spots) >= len(params.objects)
    d = np.linalg.norm(spots[:, None, :2] - spots[None, :, :2], axis=2) + np.eye(len(spots))
    assert d.min() >= 2 * r + params.place.gap - 1e-9  # footprints never touch, whatever the yaw
    # inside bin_b's walls (x 0.34..0.66, y 0.04..0.48 inside) with the gap, on its 1 cm floor
    assert np.all(spots[:, 0] - r - params.place.gap >= 0.34 + 0.01 - 1e-9)
    assert np.all(spots[:, 1] + r + params.place.gap <= 0.48 - 0.01 + 1e-9)
    assert spots[:, 2] == pytest.approx(0.01)


def test_overlapping_regions_and_a_region_reaching_into_a_wall_are_refused(tmp_path, bin_to_bin):
    def change(d):
        objs = d["pick_place_many"]["objects"]
        objs[1]["position"] = [0.49, -0.38, 0.035]  # 5 cm from 'red': their regions overlap
        objs[2]["region"]["xy_range"] = [0.2, 0.0]  # 'blue' can be spawned into bin_a's x walls
    problems = _problems(_variant(tmp_path, bin_to_bin, change))
    msgs = {p.path: p.message for p in problems}
    assert "objects 'green' and 'red' can be spawned into each other" in msgs["pick_place_many.objects[1].region"]
    assert "object 'blue' can be spawned into 'bin_a/wall_" in msgs["pick_place_many.objects[2].region"]
    assert all(p.line is not None for p in problems)


def test_an_unknown_place_fixture_and_a_full_bin_are_refused(tmp_path, bin_to_bin):
    def unknown(d):
        d["pick_place_many"]["place"]["fixture"] = "bin_c"
    (p,) = _problems(_variant(tmp_path, bin_to_bin, unknown))
    assert p.path == "pick_place_many.place.fixture" and "did you mean 'bin_b'" in p.message and "known: bin_a, bin_b" in p.message

    def full(d):
        d["pick_place_many"]["place"]["gap"] = 0.1
    (p,) = _problems(_variant(tmp_path, bin_to_bin, full))
    assert p.path == "pick_place_many.place.gap" and "holds 1 of the 5 objects" in p.message


def test_an_object_out_of_reach_is_refused_before_simulating(tmp_path, bin_to_bin):
    def far(d):
        d["pick_place_many"]["objects"].append({"name": "far", "shape": "box", "size": [0.05, 0.05, 0.05],
                                               "position": [1.5, 0.0, 0.025]})
        d["pick_place_many"]["place"]["gap"] = 0.01
    task = load_task(_variant(tmp_path, bin_to_bin, far))
    with pytest.raises(ConfigError) as exc:
        PickPlaceManyRunner(task, RunOptions(seed=0)).check()
    assert any(p.path == "pick_place_many.objects[5].position" and "object 'far'" in p.message
               and "out of the arm's reach (nominal point" in p.message for p in exc.value.problems)


def test_validate_reports_the_reach_error_that_run_refuses(tmp_path, bin_to_bin, capsys, monkeypatch):
    """``validate`` makes the same IK reach check as ``run`` (before simulating): exit 2, the
    object's position line, with the phase."""
    from _cli import run_main

    def far(d):
        d["pick_place_many"]["objects"][0]["position"] = [1.5, 0.0, 0.025]
    path = _variant(tmp_path, bin_to_bin, far)
    code, _out, err = run_main(["validate", str(path)], capsys, monkeypatch)
    assert code == 2
    assert "pick_place_many.objects[0].position: pre_grasp: object 'red'" in err
    assert "out of the arm's reach (nominal point" in err
    code, _out, err = run_main(["validate", str(bin_to_bin.path)], capsys, monkeypatch)
    assert code == 0, err


def test_bin_to_bin_places_all_five_without_touching_a_fixture(bin_to_bin):
    runner = PickPlaceManyRunner(bin_to_bin, RunOptions(seed=0, episodes=1))
    runner.check()
    (ep,) = runner.run().report.episodes
    assert ep.success, ep.reason
    assert ep.placed == 5 and ep.order == ["red", "green", "blue", "yellow", "purple"]
    assert ep.robot_fixture_contacts == 0, ep.first_contact
    for o in ep.objects:
        assert o.success and o.place_error < 0.02 and o.tilt_deg < 15, o
        assert 0.04 < o.final[1] < 0.48 and o.final[2] < 0.06  # inside bin_b, resting low (not on another object)
        assert o.grasp_candidates > 0 and [p.name for p in o.phases][-1] == "retract"
    finals = np.array([o.final[:2] for o in ep.objects])
    gaps = np.linalg.norm(finals[:, None] - finals[None], axis=2) + np.eye(5)
    assert gaps.min() > 0.07  # on separate spots


def test_shelf_placing_puts_each_object_on_the_level_and_withdraws_through_the_front():
    task = load_task(catalog.find("tasks", "pick_place_shelf"))
    (ep,) = PickPlaceManyRunner(task, RunOptions(seed=0, episodes=1)).run().report.episodes
    assert ep.success, ep.reason
    assert ep.robot_fixture_contacts == 0, ep.first_contact
    for o, half in zip(ep.objects, (0.025, 0.025, 0.02), strict=True):
        # on level 1 (top face 0.2 m), inside the shelf (x 0.49..0.73, y -0.03..0.73 between the sides)
        assert o.final[2] == pytest.approx(0.2 + half, abs=0.003) and o.tilt_deg < 5, o
        assert 0.49 < o.final[0] < 0.73 and -0.03 < o.final[1] < 0.73
        assert [p.name for p in o.phases][-2:] == ["retract", "withdraw"]


def test_clear_table_picks_by_reachability_with_grasps_clear_of_the_neighbours():
    task = load_task(catalog.find("tasks", "clear_table"))
    (ep,) = PickPlaceManyRunner(task, RunOptions(seed=0, episodes=1)).run().report.episodes
    assert ep.success, ep.reason
    assert ep.placed == 5 and sorted(ep.order) == sorted(o.name for o in task.config.pick_place_many.objects)
    assert ep.order != [o.name for o in task.config.pick_place_many.objects]  # not simply the listed order
    assert sum(o.grasps_in_collision for o in ep.objects) > 0  # the close neighbours did rule grasps out
    assert ep.robot_fixture_contacts == 0, ep.first_contact


def test_grasps_the_filter_drops_touch_a_neighbour_in_pybullet_too(monkeypatch):
    """The clutter filter (pinocchio + coal hulls) against PyBullet's own collision detection: each
    configuration it rejects or accepts is rebuilt in a second PyBullet world (same object poses,
    arm at the configuration, fingers open) and measured there."""
    from robocfg.runners import pick_place_many_machine as machine
    from robocfg.sim.world import World

    task = load_task(catalog.find("tasks", "clear_table"))
    twin = World(task)
    arm = twin.robot.arm()
    arm.require_gripper().open()
    twin.step(120)  # fingers open
    seen: list[tuple[bool, float]] = []
    free = machine.ClutterFilter.free

    def spy(self, world, target, q_pre, q_grasp):
        ok = free(self, world, target, q_pre, q_grasp)
        names = [b.name for b in task.config.pick_place_many.objects if b.name != target]
        for n in names:
            pos, quat = world.body_pose(n)
            if n not in twin.bodies:
                twin.add_body(task.config.pick_place_many.objects[[b.name for b in task.config.pick_place_many.objects].index(n)])
            twin.set_body_pose(n, pos, quat)
        if target in twin.bodies:
            twin.remove_body(target)
        others = names + [b for b in twin.bodies if "/" in b]
        gaps = []
        for q in (q_pre, q_grasp):
            twin.robot.reset_joints(arm.joints, q)
            gaps += [c.distance for b in others for c in twin.closest_points(twin.robot.body_id, b, 0.05)]
        seen.append((ok, min(gaps, default=0.05)))
        return ok

    monkeypatch.setattr(machine.ClutterFilter, "free", spy)
    try:
        PickPlaceManyRunner(task, RunOptions(seed=0, episodes=1)).run()
    finally:
        twin.close()
    rejected = [d for ok, d in seen if not ok]
    accepted = [d for ok, d in seen if ok]
    margin = task.config.pick_place_many.clutter_margin
    assert rejected and accepted
    assert all(d < margin + 0.004 for d in rejected), rejected  # PyBullet finds them close (hulls: ±4 mm)
    assert all(d > 0.001 for d in accepted), min(accepted)  # and the kept ones clear


def test_an_episode_gives_the_same_record_alone_or_after_another(bin_to_bin):
    """Same seed ⇒ same record, whatever ran before it in the world (what --workers and --resume
    rely on): the objects are spawned per episode, the planner's model refreshed per move."""
    from robocfg.engine import open_session

    with open_session(bin_to_bin, RunOptions(seed=5)) as session:
        session.run(0)
        after = session.run(1)
    with open_session(bin_to_bin, RunOptions(seed=5)) as session:
        alone = session.run(1)
    assert after == alone


def test_a_clear_table_episode_gives_the_same_record_alone_or_after_another():
    """Objects standing 2.5–4 cm apart: after a restore, Bullet's broadphase pair order followed the
    world's history (bodies removed and re-added per episode) and episode 1 after episode 0 ended
    with the objects micrometres away from episode 1 alone (UR5e + 2F-85, seed 0); the session now
    builds a new world per episode (``fresh_world_per_episode``)."""
    from robocfg.engine import open_session

    task = load_task(catalog.find("tasks", "clear_table"), robot_override="ur5e_robotiq_2f85")
    with open_session(task, RunOptions(seed=0)) as session:
        session.run(0)
        after = session.run(1)
    with open_session(task, RunOptions(seed=0)) as session:
        alone = session.run(1)
    assert after.success and after == alone


def test_contact_watch_counts_touching_points_not_the_near_ones_pybullet_also_reports():
    """PyBullet's ``getContactPoints`` also returns points still apart (positive distance): the
    watch counts only polls with a point at distance ≤ 0, by phase and link, and keeps the
    closest distance. A static box is raised in 0.25 mm steps under the Panda's forearm
    (``panda_link5``) from 5 mm below its bounding box to 5 mm into it, one poll per step."""
    from robocfg.config.scene import Body
    from robocfg.runners.pick_place_many_machine import SETTLE_POLL, ContactWatch
    from robocfg.sim.world import World

    world = World(load_task(catalog.find("tasks", "pick_place_shelf")))
    try:
        world.step(1)
        robot = world.robot
        lo, hi = world.aabb(robot.body_id, robot.link("panda_link5"))
        x, y = (lo[:2] + hi[:2]) / 2
        world.add_body(Body(name="probe", shape="box", size=[0.1, 0.1, 0.02], position=[x, y, lo[2] - 0.1],
                            mass=0.0), static=True)
        watch = ContactWatch(world, ["probe"], lambda: "lower")
        seen: list[tuple[float | None, int]] = []  # (closest reported distance, polls counted so far)
        for top in np.arange(-0.005, 0.00501, 0.00025):
            world.set_body_pose("probe", [x, y, lo[2] + top - 0.01])
            for _ in range(SETTLE_POLL):
                world.step(1)
                watch.on_step()
            pts = world.contact_points(robot.body_id, "probe")
            seen.append((min((p.distance for p in pts), default=None), watch.count))
        counted = [c1 - c0 for (_, c0), (_, c1) in zip([(None, 0), *seen], seen, strict=False)]
        for (d, _), c in zip(seen, counted, strict=True):
            assert c == (1 if d is not None and d <= 0 else 0), (d, c)
        assert any(d is not None and d > 0 for d, _ in seen)  # PyBullet did report points still apart
        assert watch.count == sum(d is not None and d <= 0 for d, _ in seen) > 0
        assert watch.first == "lower: panda_link5 touched probe" and watch.by_kind == {watch.first: watch.count}
        assert watch.closest == pytest.approx(min(d for d, _ in seen if d is not None))
    finally:
        world.close()
