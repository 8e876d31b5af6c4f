"""robocfg.sim.same_step: a read kept while the world's state cannot have changed, and read again
after every kind of change (a step in each loop, teleports, bodies added or removed, a restore,
a robot's reset_joints and the resets that go through it)."""

from __future__ import annotations

import numpy as np
import pytest
from _sim_helpers import PANDA, make_task

import robocfg
from robocfg.config.scene import Body
from robocfg.engine import RunOptions, open_session
from robocfg.sim.same_step import SameStepReads
from robocfg.sim.world import World

CUBE = {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.2, "position": [0.6, 0.3, 0.2]}


@pytest.fixture()
def world(tmp_path):
    with World(make_task(tmp_path, PANDA, objects=[CUBE])) as w:
        w.step(1)
        yield w


def _counted(world: World):
    """A SameStepReads and a read of the cube's height that counts its PyBullet queries."""
    calls = []

    def read():
        calls.append(world.steps)
        return world.body_pose_tuple(world.bodies["cube"])[0][2]

    return SameStepReads(world), read, calls


def test_a_value_is_read_once_per_state(world):
    reads, read, calls = _counted(world)
    z = reads.get("z", read)
    assert reads.get("z", read) == z and len(calls) == 1  # nothing changed: the first read's value
    assert reads.get("other", lambda: 7) == 7 and reads.get("z", read) == z and len(calls) == 1
    world.robot.arm().command(world.robot.arm().home + 0.1)  # a motor command changes nothing before a step
    assert reads.get("z", read) == z and len(calls) == 1


def _step(w: World) -> None:
    w.step(1)


def _steps_idle(w: World) -> None:
    w.step(5)  # advance_idle's bare loop


def _play_bare(w: World) -> None:
    arm = w.robot.arm()
    q = np.tile(arm.joint_positions(), (3, 1))
    w.play(arm, q, np.zeros_like(q))


def _play_hooked(w: World) -> None:
    arm = w.robot.arm()
    q = np.tile(arm.joint_positions(), (3, 1))
    w.play(arm, q, np.zeros_like(q), after=lambda: None)


def _teleport(w: World) -> None:
    w.set_body_pose("cube", [0.6, 0.3, 0.5])


def _add(w: World) -> None:
    w.add_body(Body(name="ball", shape="sphere", size=[0.03], mass=0.1, position=[0.4, -0.3, 0.03]))


def _remove(w: World) -> None:
    _add(w)
    w.step(1)
    reads_after_add = w.read_stamp
    w.remove_body("ball")
    assert w.read_stamp != reads_after_add


def _restore(w: World) -> None:
    state = w.snapshot()
    w.step(3)
    w.restore(state)


def _reset_joints(w: World) -> None:
    arm = w.robot.arm()
    w.robot.reset_joints(arm.joints[:1], [0.3])


def _gripper_reset(w: World) -> None:
    w.robot.arm().gripper.reset(0.0)  # teleports the fingers (through reset_joints)


CHANGES = [_step, _steps_idle, _play_bare, _play_hooked, _teleport, _add, _remove, _restore, _reset_joints,
           _gripper_reset]


@pytest.mark.parametrize("change", CHANGES, ids=[c.__name__.strip("_") for c in CHANGES])
def test_every_change_of_state_is_read_again(world, change):
    reads, read, calls = _counted(world)
    joints = SameStepReads(world)
    arm = world.robot.arm()
    reads.get("z", read)
    q_before = joints.get("q", arm.robot.joint_positions)
    stamp = world.read_stamp
    change(world)
    assert world.read_stamp != stamp
    z = reads.get("z", read)
    assert len(calls) == 2 and z == world.body_pose_tuple(world.bodies["cube"])[0][2]
    q = joints.get("q", arm.robot.joint_positions)
    assert np.array_equal(q, arm.robot.joint_positions())
    if change in (_reset_joints, _gripper_reset):
        assert not np.array_equal(q, q_before)  # the kept value would have been stale


def test_a_restore_to_step_zero_is_not_taken_for_the_state_before_it(world):
    """steps go back to 0 at a restore: the teleport count tells the two states apart."""
    state = world.snapshot()
    world.restore(state)
    reads, read, calls = _counted(world)
    reads.get("z", read)
    world.step(2)
    world.set_body_pose("cube", [0.6, 0.3, 0.4])
    world.restore(state)  # steps 0 again, and the same number of steps as at the first read
    reads.get("z", read)
    assert len(calls) == 2


def test_touching_with_one_query_answers_as_one_query_per_link(world):
    """SceneQueries.touching reads a's contacts with b once and sorts them by link: the same answer
    as asking link by link (a cube falling onto the ground and resting there; the robot's links
    against the ground, all of them and one at a time)."""
    import pybullet as p

    def per_link(a, b, links):
        return any(c[8] <= 0.0 for link in links for c in p.getContactPoints(a, b, link, physicsClientId=world.client))

    robot, cube, ground = world.robot, world.bodies["cube"], world.bodies["ground"]
    link_sets = [[-1], *[[i] for i in robot.link_index.values()], list(robot.link_index.values())]
    answers = []
    for _ in range(60):
        world.step(2)
        for a, links in [(cube, [-1]), (cube, [0]), *((robot.body_id, links) for links in link_sets)]:
            got = world.touching(a, ground, links)
            assert got == per_link(a, ground, links)
            answers.append(got)
    assert True in answers and False in answers  # both answers were checked


def test_a_pick_place_episode_reads_each_state_once_where_it_asked_twice(monkeypatch):
    """The reads the mover shares: the episode asks PyBullet for the object's pose, the EE pose,
    the arm's joints and the finger gap no more than once per physics state (before: the same
    state was read twice for each, 5 an episode)."""
    import pybullet as p

    log, worlds = [], []
    for name in ("getBasePositionAndOrientation", "getLinkState", "getJointStates", "getClosestPoints"):
        real = getattr(p, name)

        def spy(*a, _real=real, _name=name, **k):
            if worlds:
                log.append((_name, (worlds[0].steps, getattr(worlds[0], "teleports", 0)), a[:2]))
            return _real(*a, **k)

        monkeypatch.setattr(p, name, spy)
    task = robocfg.load_task("pick_place")
    with open_session(task, RunOptions(seed=0)) as session:
        worlds.append(session.world)
        record = session.run(1)
    assert record.success
    repeated = [e for i, e in enumerate(log) if e in log[:i]]
    assert repeated == []
