"""Worlds nothing draws load their robots without visual meshes (``World(visuals=False)``, PyBullet's
``URDF_IGNORE_VISUAL_SHAPES``) and without PyBullet's TinyRenderer (``robocfg.sim.renderer``): the
physics is the same bit for bit, drawing such a world is an error rather than a blank picture, and
every session that draws (a recording, a dataset with cameras, grasp perception) still loads them."""

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
from robocfg.errors import RobocfgError
from robocfg.sim import renderer
from robocfg.sim.record_camera import CameraView, render
from robocfg.sim.render_mirror import RenderMirror
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
        # the plain world has no renderer, so no visual shapes at all (robocfg.sim.renderer)
        assert renderer.has_renderer(drawn.world.client) and not renderer.has_renderer(plain.world.client)
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


def test_a_world_without_renderer_refuses_to_draw() -> None:
    """Pictures of a world built without its renderer would be blank: drawing it raises, and a
    client id reused after the world closes draws again."""
    task = load_task(catalog.find("tasks", "pick_place"))
    with World(task, visuals=False) as w:
        c = w.client
        assert not renderer.has_renderer(c)
        with pytest.raises(RobocfgError, match="without a renderer"):
            render(c, CameraView(), (32, 24))
        with pytest.raises(RobocfgError, match="without a renderer"):
            RenderMirror(c)  # a dataset camera's mirror reads the world's visual shapes
    assert renderer.has_renderer(c)
    with World(task, visuals=True) as w:
        assert w.client == c and renderer.has_renderer(c)
        img = render(c, CameraView(), (32, 24))
        assert img.shape == (24, 32, 3) and len(np.unique(img.reshape(-1, 3), axis=0)) > 1  # not blank
