"""The finger jam on release (issue 18): PyBullet keeps a pair's contact points across steps and can
keep one whose normal turned round inside a finger's convex hull, which holds the opening fingers
on the object. The release rebuilds the fingers' contacts from the geometry when they stall."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
from robocfg.sim.world import World


def test_refresh_contacts_rebuilds_the_pairs_contacts_and_moves_nothing():
    task = load_task(catalog.find("tasks", "pick_place"))
    with World(task) as world:
        cube = world.add_body(task.config.pick_place.object)
        world.step(120)  # resting on the ground
        before = [world.body_pose(cube), world.body_velocity(cube)]
        touching = world.contact_points(cube, "ground")
        assert touching and world.touching(cube, "ground", [-1])
        world.refresh_contacts(cube, "ground", [-1])
        after = [world.body_pose(cube), world.body_velocity(cube)]
        for x, y in zip(before, after, strict=True):
            assert np.array_equal(x[0], y[0]) and np.array_equal(x[1], y[1])
        fresh = world.contact_points(cube, "ground")
        assert fresh and min(c.distance for c in fresh) == pytest.approx(min(c.distance for c in touching), abs=1e-4)
        world.step(60)  # the pair still collides: the cube stays on the ground
        assert abs(world.body_pose(cube)[0][2] - before[0][0][2]) < 1e-3


def test_a_release_whose_fingers_stall_on_the_object_rebuilds_their_contacts_and_lets_go(monkeypatch):
    """Shelf placing, seed 0, episode 8, with the set-down switched off (the object let go while it
    hangs 1 mm above the board, as before the set-down existed): on this machine's PyBullet the
    Panda's fingers stall at 2/3 open on the red box (``release: the object did not come free``
    without the rebuild). With it, all three objects are placed."""
    from robocfg.runners import pick_place_many_machine as machine
    from robocfg.sim.gripper.parallel import ParallelGripper

    monkeypatch.setattr(machine.ObjectMachine, "_set_down", lambda self: None)
    rebuilt: list[float] = []
    refresh = ParallelGripper.refresh_contacts

    def spy(self, body, touching_only=False):
        done = refresh(self, body, touching_only)
        if done and not touching_only:
            rebuilt.append(self.fraction())
        return done

    monkeypatch.setattr(ParallelGripper, "refresh_contacts", spy)
    task = load_task(catalog.find("tasks", "pick_place_shelf"))
    with open_session(task, RunOptions(seed=0)) as session:
        record = session.run(8)
    if record.success and not rebuilt:
        pytest.skip("the fingers did not stall in this episode on this PyBullet build (no jam to undo)")
    assert record.success, record.reason  # without the rebuild: "release: red: the object did not come free"
    assert all(0.3 < f < 0.9 for f in rebuilt), rebuilt  # stalled part-way open, not at an end


def test_an_open_finger_still_touching_the_released_object_does_not_drag_it_up(monkeypatch):
    """Shelf placing, seed 1, episode 0, set-down off: the fingers open, but one keeps a contact
    point with the red box; on this machine's PyBullet the retract then lifts the box with it
    (``retract: red: the released object rose 4.9 cm with the fingers`` without the rebuild).
    With the finger's contacts rebuilt before the hand moves, the box stays and all three are placed."""
    from robocfg.runners import pick_place_many_machine as machine
    from robocfg.sim.gripper.parallel import ParallelGripper

    monkeypatch.setattr(machine.ObjectMachine, "_set_down", lambda self: None)
    rebuilt: list[float] = []
    refresh = ParallelGripper.refresh_contacts

    def spy(self, body, touching_only=False):
        done = refresh(self, body, touching_only)
        if done and touching_only:
            rebuilt.append(self.fraction())
        return done

    monkeypatch.setattr(ParallelGripper, "refresh_contacts", spy)
    task = load_task(catalog.find("tasks", "pick_place_shelf"))
    with open_session(task, RunOptions(seed=1)) as session:
        record = session.run(0)
    if record.success and not rebuilt:
        pytest.skip("no finger touched the released object in this episode on this PyBullet build")
    assert record.success, record.reason  # without the rebuild: "retract: red: the released object rose 4.9 cm ..."
    assert rebuilt and all(f >= 0.9 for f in rebuilt), rebuilt  # rebuilt once open, before the retract
