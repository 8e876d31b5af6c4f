"""Pick-place with ``motion: planned``: the global planner carries the cube round the wall of the
obstacle task (held cube attached to the hand's collision model), and nothing touches the wall."""

from dataclasses import replace

import numpy as np
import pytest
from _sim_helpers import ContactSpy, run_spied

from robocfg.checks import load_task
from robocfg.config import catalog


@pytest.fixture(scope="module")
def task():
    return load_task(catalog.find("tasks", "pick_place_obstacle_planned"))


def test_the_planned_task_is_the_obstacle_scene(task):
    reactive = load_task(catalog.find("tasks", "pick_place_obstacle"))
    assert task.config.pick_place.motion == "planned"
    assert task.config.scene == reactive.config.scene


def _run(task, seed: int, episodes: int = 1):
    return run_spied(task, ContactSpy, seed, episodes)


@pytest.mark.parametrize("seed", [0, 3])
def test_planned_transport_goes_round_the_wall(task, seed):
    report, spy = _run(task, seed)
    episode = report.episodes[0]
    assert episode.success, (episode.failed_phase, episode.reason)
    assert [p.name for p in episode.phases][:5] == ["pre_grasp", "approach", "grasp", "lift", "transport"]
    assert spy.checked > 500
    assert spy.robot_hits == 0
    assert spy.cube_hits == 0


def test_same_seed_same_report(task):
    a, _ = _run(task, 5, episodes=2)
    b, _ = _run(task, 5, episodes=2)
    assert a == b


def test_place_behind_a_wall_fails_transport_naming_the_wall(task):
    """A wall too tall and long to pass, between the pick and the place point: every arm pose
    above the place point crosses it, so the transport phase fails before moving, naming the wall."""
    scene = task.config.scene
    wall = scene.obstacles[0].model_copy(update={"size": [4.0, 0.04, 1.6], "position": [0.0, 0.17, 0.8]})
    blocked = replace(task, config=task.config.model_copy(update={"scene": scene.model_copy(update={"obstacles": [wall]})}))
    report, spy = _run(blocked, 0)
    episode = report.episodes[0]
    assert not episode.success
    assert episode.failed_phase == "transport", episode.reason
    assert episode.reason.startswith("the goal configuration is in collision (panda_link")
    assert "with wall" in episode.reason
    assert spy.robot_hits == 0 and spy.cube_hits == 0


def test_a_loose_object_in_the_way_is_gone_round_not_pushed(task):
    """The wall as a loose 2 kg block (``scene.objects``): the planner keeps the arm and the cube
    clear of it where it stands, so it is never touched and stays put."""
    scene = task.config.scene
    wall = scene.obstacles[0]
    block = wall.model_copy(update={"name": "block", "mass": 2.0})
    loose = replace(task, config=task.config.model_copy(update={"scene": scene.model_copy(update={"obstacles": [], "objects": [block]})}))

    class BlockSpy(ContactSpy):
        def maybe_capture(self):
            super().maybe_capture()
            self.block_at = self.world.body_pose("block")[0]

    report, spy = run_spied(loose, lambda world: BlockSpy(world, obstacle="block"))
    episode = report.episodes[0]
    assert episode.success, (episode.failed_phase, episode.reason)
    assert spy.checked > 500 and spy.robot_hits == 0 and spy.cube_hits == 0
    assert np.allclose(spy.block_at, block.position, atol=1e-3)


def test_a_planned_move_carries_a_held_load_no_harder_than_the_grip_allows(task):
    """``ArmMover.max_acceleration`` (what the grip carries, set after the grasp) bounds the EE's
    acceleration on planned moves too: the planned, timed path is slowed uniformly along the same
    joint path until the EE's peak acceleration (dense FK samples) is within it."""
    from robocfg.config.commands import Limits
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.limits import limits_from_robot
    from robocfg.motion.moves import ArmMover
    from robocfg.planning.drive import build_planned_drive
    from robocfg.sim.world import World

    with World(task) as world:
        arm = world.robot.arm()
        kin = KinematicModel.from_robot(world.robot.checked)
        limits = limits_from_robot(world.robot.checked, arm.joints, Limits())
        mover = ArmMover(world, arm, kin, limits)
        drive = build_planned_drive(world.robot.checked, world, kin)
        q0 = arm.joint_positions()
        T = kin.fk(q0, "ee")
        T[:3, 3] += [0.0, 0.25, -0.1]
        plan = drive.planner.timed(drive.planner.plan(q0, drive.goal(mover, T, q0)), limits)
        free = plan.trajectory
        assert mover.slowed_for_load(free) is free  # no load limit: unchanged

        def peak(traj) -> float:
            t = np.linspace(0.0, traj.duration, 801)
            P = kin.fk_positions(traj.evaluate(t)[0], "ee")
            return float(np.linalg.norm(np.diff(P, 2, axis=0), axis=1).max()) / (t[1] - t[0]) ** 2

        mover.max_acceleration = 0.25 * peak(free)
        slow = mover.slowed_for_load(free)
        assert slow.duration > 1.9 * free.duration
        assert peak(slow) <= 1.05 * mover.max_acceleration
        for s in (0.0, 0.3, 0.7, 1.0):  # the same joint path, later
            assert np.allclose(slow.evaluate(s * slow.duration)[0], free.evaluate(s * free.duration)[0])
        t0 = world.t
        drive.move(mover, T)  # the drive plays the slowed timing
        assert world.t - t0 >= slow.duration - world.dt
