"""Worlds nothing draws load their robots without visual meshes (``World(visuals=False)``, PyBullet's
``URDF_IGNORE_VISUAL_SHAPES``): the physics is the same bit for bit, and every session that draws
(a recording, a dataset with cameras, grasp perception) still loads them."""

from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pybullet as p
import pytest
from _sim_helpers import SHIPPED_ROBOTS, make_task

from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
from robocfg.engine.options import EpisodeObserver
from robocfg.sim.world import World


def _state(world: World) -> bytes:
    """Every body's pose and velocity and every joint's position, velocity and reaction force."""
    c, out = world.client, []
    for i in range(p.getNumBodies(physicsClientId=c)):
        b = p.getBodyUniqueId(i, physicsClientId=c)
        out.append(p.getBasePositionAndOrientation(b, physicsClientId=c))
        out.append(p.getBaseVelocity(b, physicsClientId=c))
        n = p.getNumJoints(b, physicsClientId=c)
        if n:
            out.append(p.getJointStates(b, list(range(n)), physicsClientId=c))
    return repr(out).encode()


class _Hasher(EpisodeObserver):
    """A SHA-1 over the world's whole state after every physics step."""

    def __init__(self, world: World):
        self.world, self.sha, self.steps = world, hashlib.sha1(), 0

    def maybe_capture(self) -> None:
        self.sha.update(_state(self.world))
        self.steps += 1


def _visual_files(world: World) -> set[str]:
    return {vs[4].decode() for vs in p.getVisualShapeData(world.robot.body_id, physicsClientId=world.client)}


def test_pick_place_episode_is_the_same_without_visual_meshes() -> None:
    """Episode 0 of the shipped pick-place task: a recorder (which draws) gets the visual meshes,
    a plain run does not; every physics step's state and the report are identical."""
    task = load_task(catalog.find("tasks", "pick_place"))
    hashers: list[_Hasher] = []

    def factory(world: World) -> _Hasher:
        hashers.append(_Hasher(world))
        return hashers[-1]

    drawn = open_session(task, RunOptions(seed=0, recorder=factory))
    plain = open_session(task, RunOptions(seed=0))
    try:
        assert drawn.world.visuals and not plain.world.visuals
        assert any("/visual/" in f for f in _visual_files(drawn.world))
        assert not any("/visual/" in f for f in _visual_files(plain.world))  # collision shapes drawn instead
        mine = _Hasher(plain.world)
        plain.world.step_hooks.append(mine.maybe_capture)
        a, b = drawn.run(0), plain.run(0)
        assert a.success and b.success
        assert hashers[0].steps == mine.steps > 1000
        assert hashers[0].sha.hexdigest() == mine.sha.hexdigest()
        assert a == b and dataclasses.asdict(drawn.report([a], False)) == dataclasses.asdict(plain.report([b], False))
    finally:
        drawn.close()
        plain.close()


@pytest.mark.parametrize("robot", SHIPPED_ROBOTS, ids=lambda r: r.stem)
def test_every_robot_has_the_same_dynamics_and_shapes_without_visuals(tmp_path, robot) -> None:
    """Masses, inertias, friction, collision shapes (the robot's and the ground's) and 60 steps
    of a moving arm are identical."""
    task = make_task(tmp_path, robot)
    states = []
    for visuals in (True, False):
        with World(task, visuals=visuals) as w:
            c, body = w.client, w.robot.body_id
            links = range(-1, p.getNumJoints(body, physicsClientId=c))
            facts = [(p.getDynamicsInfo(body, li, physicsClientId=c), p.getCollisionShapeData(body, li, physicsClientId=c),
                      p.getAABB(body, li, physicsClientId=c)) for li in links]
            g = w.bodies["ground"]  # the plane loads without its textured mesh too
            facts.append((p.getDynamicsInfo(g, -1, physicsClientId=c), p.getCollisionShapeData(g, -1, physicsClientId=c)))
            arm = w.robot.arm()
            arm.command(np.asarray(arm.home, float) + 0.2)
            w.step(60)
            states.append((repr(facts), _state(w)))
    assert states[0] == states[1]


def test_sessions_that_draw_load_the_visual_meshes(tmp_path) -> None:
    task = load_task(catalog.find("tasks", "pick_place"))
    for options, visuals in ((RunOptions(record=tmp_path / "x.gif"), True), (RunOptions(), False)):
        s = open_session(task, options)
        try:
            assert s.world.visuals is visuals
        finally:
            s.close()
    grasp = load_task(catalog.find("tasks", "grasp"))
    s = open_session(grasp, RunOptions())
    try:
        assert s.world.visuals  # grasp perception's depth camera sees the robot as drawn
    finally:
        s.close()
