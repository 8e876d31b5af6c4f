"""RenderMirror: low-poly, baked-background copies of real worlds draw the same picture as the
world itself, follow the robot and the bodies, and re-bake a static body that moves."""

from pathlib import Path

import numpy as np
import pybullet as p
import pybullet_data
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.config.scene import Body
from robocfg.sim.low_poly import low_poly
from robocfg.sim.record import Recorder
from robocfg.sim.record_camera import render, scene_camera, view_projection
from robocfg.sim.render_mirror import RenderMirror
from robocfg.sim.world import World

SIZE = (240, 180)


@pytest.fixture(scope="module")
def world():
    task = load_task(catalog.find("tasks", "pick_place"))
    with World(task) as w:
        w.add_body(task.config.pick_place.object)
        yield w


def _differing(a: np.ndarray, b: np.ndarray, tol: int = 40) -> float:
    """Fraction of pixels whose colour differs by more than ``tol`` in some channel."""
    return float((np.abs(a.astype(int) - b.astype(int)).max(axis=2) > tol).mean())


def test_mirror_draws_the_same_picture_as_the_world(world):
    cam = scene_camera(world, SIZE)
    view, proj = view_projection(world.client, cam, SIZE)
    direct = render(world.client, cam, SIZE)
    with RenderMirror(world.client, max_faces=None) as exact, RenderMirror(world.client) as fast:
        same = exact.render(view, proj, SIZE)
        low = fast.render(view, proj, SIZE)
        assert fast.proxies and all(pr.links for pr in fast.proxies.values())
    assert _differing(same, direct) < 0.005  # baked background + depth merge: the same image
    assert _differing(low, direct) < 0.03  # low-poly meshes: edges move by a pixel here and there
    robot_pixels = _differing(direct, render_without_robot(world, cam))
    assert robot_pixels > 0.02  # the comparison above is not of two empty floors


def render_without_robot(world, cam) -> np.ndarray:
    """The same view of a world with the ground and the cube only."""
    c = p.connect(p.DIRECT)
    try:
        p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), physicsClientId=c)
        return render(c, cam, SIZE)
    finally:
        p.disconnect(physicsClientId=c)


def test_mirror_follows_the_robot_and_objects(world):
    state = world.snapshot()
    cam = scene_camera(world, SIZE)
    view, proj = view_projection(world.client, cam, SIZE)
    arm = world.robot.arm()
    try:
        with RenderMirror(world.client) as mirror:
            before = mirror.render(view, proj, SIZE)
            q = np.array(arm.home, float)
            q[0] += 0.8
            q[1] += 0.4
            world.robot.reset_joints(arm.joints, q.tolist(), hold=False)
            cube = world.body_id(world.task.config.pick_place.object.name)
            p.resetBasePositionAndOrientation(cube, [0.3, 0.3, 0.02], [0, 0, 0, 1], physicsClientId=world.client)
            after = mirror.render(view, proj, SIZE)
            direct = render(world.client, cam, SIZE)
        assert _differing(before, after) > 0.01  # the arm swung: the picture changed
        assert _differing(after, direct) < 0.03  # and it matches the world drawn directly
    finally:
        world.restore(state)


def test_a_static_body_that_moves_is_baked_again(world):
    cam = scene_camera(world, SIZE)
    view, proj = view_projection(world.client, cam, SIZE)
    box_id = world.add_body(Body(name="crate", shape="box", size=[0.12, 0.12, 0.12], mass=0.0,
                                 color=[0.1, 0.2, 0.9, 1], position=[0.45, -0.3, 0.06]), static=True)
    with RenderMirror(world.client) as mirror:
        first = mirror.render(view, proj, SIZE)
        assert mirror.proxies[box_id].pose  # a static body: drawn into the background
        p.resetBasePositionAndOrientation(box_id, [0.45, 0.3, 0.06], [0, 0, 0, 1], physicsClientId=world.client)
        moved = mirror.render(view, proj, SIZE)
        assert not mirror.proxies[box_id].pose  # now drawn every frame
        direct = render(world.client, cam, SIZE)
    assert _differing(first, moved) > 0.002
    assert _differing(moved, direct) < 0.03
    world.remove_body("crate")


def test_low_poly_keeps_colours_and_caches(tmp_path):
    link = Path(pybullet_data.getDataPath()) / "franka_panda" / "meshes" / "visual" / "link6.obj"
    parts = low_poly(str(link), (1.0, 1.0, 1.0, 1.0), max_faces=800)
    faces = sum(sum(1 for ln in Path(pt.path).read_text().splitlines() if ln.startswith("f ")) for pt in parts)
    assert 0 < faces <= 800 + 12 * len(parts)
    greys = sorted(float(np.mean(pt.rgba[:3])) for pt in parts)
    assert greys[0] < 0.4 and greys[-1] > 0.8  # the dark joint cap and the white shell both survive
    stamp = [Path(pt.path).stat().st_mtime_ns for pt in parts]
    again = low_poly(str(link), (1.0, 0.5, 0.5, 1.0), max_faces=800)
    assert [Path(pt.path).stat().st_mtime_ns for pt in again] == stamp  # read from the cache
    assert again[0].rgba[1] == pytest.approx(parts[0].rgba[1] * 0.5)  # the shape's own colour tints
    small = Path(pybullet_data.getDataPath()) / "cube.obj"
    assert [pt.path for pt in low_poly(str(small))] == [str(small)]  # small meshes are drawn as they are


def test_recorder_uses_the_mirror_and_frees_it(world, tmp_path):
    rec = Recorder(world, tmp_path / "one.gif", size=SIZE)
    rec.capture()
    assert rec._mirror is not None
    rec.save()
    assert rec._mirror is None and (tmp_path / "one.gif").stat().st_size > 0
