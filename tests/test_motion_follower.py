"""robocfg.motion.follower in PyBullet: the matched feed-forward tracks to ~1e-5 rad; the naive
"command the next sample" follower is one physics step off (≈ dt·q̇)."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.motion.follower import follow
from robocfg.motion.limits import limits_from_robot
from robocfg.motion.plan import plan_trajectory


@pytest.fixture(scope="module")
def setup():
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    task = load_task(catalog.find("tasks", "trajectory"))
    robot = task.robots[0]
    arm = robot.config.arm()
    names = robot.arm_joints(arm)
    limits = limits_from_robot(robot, names, task.config.trajectory.limits)
    W = np.array([arm.home, [0.5, 0.1, 0.2, -1.7, 0.1, 1.9, 0.9]])
    return task, names, plan_trajectory(W, limits)


def _track(task, names, traj, mode):
    from robocfg.sim.world import World

    with World(task) as world:
        q0 = traj.evaluate(0.0)[0][0]
        world.robot.reset_joints(names, q0)
        world.robot.command_positions(names, q0)
        steps = []
        tr = follow(world, names, traj, settle_time=0.1, mode=mode, on_step=lambda: steps.append(world.t))
        return tr, steps, world.dt


def test_matched_follower_tracks_closely_and_ends_on_target(setup):
    task, names, plan = setup
    tr, steps, dt = _track(task, names, plan.trajectory, "matched")
    assert tr.steps == int(np.ceil(plan.duration / dt - 1e-9))
    assert len(steps) == tr.steps + round(0.1 / dt)  # on_step after every physics step, settling included
    assert tr.rms < 1e-4 and tr.max < 2e-4 and tr.final < 1e-4 and tr.settled < 1e-4
    assert np.allclose(tr.q[-1], plan.waypoints[-1], atol=1e-4)
    assert np.max(np.abs(tr.q[len(tr.q) // 2] - tr.q[0])) > 0.2  # it really moved


def test_naive_follower_leads_by_one_step(setup):
    task, names, plan = setup
    tr, _, dt = _track(task, names, plan.trajectory, "next")
    peak_v = np.max(np.abs(plan.trajectory.sample(240.0).qd), axis=0)
    worst = int(np.argmax(peak_v))
    assert tr.max_error[worst] == pytest.approx(peak_v[worst] * dt, rel=0.25)
    assert tr.rms > 10 * _track(task, names, plan.trajectory, "matched")[0].rms
