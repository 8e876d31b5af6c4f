"""``placement: auto`` for trajectory and follow-target: points written for the Panda are moved to
the arm of a robot that cannot reach them (scaled about its arm base by the ratio of the reaches),
and left alone for a robot that reaches them."""

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.geometry import pose_matrix
from robocfg.runners.follow_target import placed_params
from robocfg.runners.trajectory import plan_task, run_trajectory


def test_trajectory_default_on_the_panda_is_unchanged():
    task = load_task(catalog.find("tasks", "trajectory"))
    assert task.config.trajectory.placement == "auto"
    *_, plan = plan_task(task)
    assert not any("placement auto" in n for n in plan.notes)


def test_trajectory_default_runs_on_a_kr210():
    """The Panda's Cartesian waypoint (0.45, 0.35, 0.4) m is out of a KR 210's reach (it fails
    with placement: world); with auto it is moved out to the KR 210's workspace and tracked."""
    from robocfg.errors import RunFailed

    world = load_task(catalog.find("tasks", "trajectory"), robot_override="kuka_kr210",
                      overrides={"trajectory.placement": "world"})
    try:
        plan_task(world)
        raise AssertionError("the desk waypoint should be out of the KR 210's reach")
    except RunFailed:
        pass
    task = load_task(catalog.find("tasks", "trajectory"), robot_override="kuka_kr210")
    result = run_trajectory(task)
    assert result.success
    assert any("moved to kuka_kr210's arm" in n for n in result.notes)


def test_follow_target_motion_and_obstacles_scale_about_the_arm_base():
    task = load_task(catalog.find("tasks", "follow_target"), robot_override="kuka_kr210")
    given = task.config.follow_target
    params, note = placed_params(task, None, given)
    assert "moved to kuka_kr210's arm" in note
    k = params.motion.radius / given.motion.radius
    assert 2.5 < k < 4.0  # ≈ 2.7 m against 0.86 m
    np.testing.assert_allclose(params.motion.center, np.asarray(given.motion.center) * k, atol=1e-9)  # both bases at 0
    for a, b in zip(params.obstacles, given.obstacles, strict=True):
        np.testing.assert_allclose(a.position, np.asarray(b.position) * k, atol=1e-9)
        np.testing.assert_allclose(a.size, np.asarray(b.size) * k, atol=1e-9)
    same, none = placed_params(load_task(catalog.find("tasks", "follow_target")), None, given)
    assert none == "" and same == given


def test_auto_steps_the_scale_down_until_every_mapped_point_is_reached(monkeypatch):
    """An arm whose reach along the ray is not one interval (the drafted Z1 reaches 0.2-0.3 m and
    0.8 m out along the default trajectory's direction, not 0.35-0.75 m): the reach ratio would put
    the waypoint in the gap; the scale steps down to the largest that IK reaches."""
    from robocfg.motion import relative

    task = load_task(catalog.find("tasks", "trajectory"), robot_override="ur5e_robotiq_2f85")
    (pose,) = [w for w in task.config.trajectory.waypoints if not isinstance(w, str)]
    given = np.asarray(pose.position)  # 0.70 m from the base

    def reaches(model, robot, arm, T, accept=None):
        d = float(np.linalg.norm(T[:3, 3]))  # both arm bases sit at the origin
        return d <= 0.3 or d >= 0.8

    monkeypatch.setattr(relative, "_reaches", reaches)
    monkeypatch.setattr(relative, "_reach", lambda model, robot, *a: 0.86 if robot.config.name == "panda" else 0.826)
    m = relative.auto_map(task, None, [pose_matrix(pose)], "Cartesian waypoints")
    assert m is not None
    d = np.linalg.norm(m.point(given))
    assert d <= 0.3  # x0.4 of the ratio 0.96: the largest step that lands where the arm reaches
    assert m.scale == pytest.approx(0.826 / 0.86 * 0.4)
    assert "x0.4 of 0.96" in m.note
