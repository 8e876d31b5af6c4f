"""Grasp outlines on recordings live in the object's frame: lift the object and they go with it."""

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.grasp.draw import BEST, OTHER, GraspRecorder, grasp_polylines
from robocfg.kinematics.frames import Grasp
from robocfg.sim.record_camera import CameraView
from robocfg.sim.world import World

CAM = CameraView(target=(0.5, 0.0, 0.1), distance=0.8, yaw_deg=50.0, pitch_deg=-30.0)
LIFT = np.array([0.0, 0.0, 0.15])  # m
SIDE = np.array([0.0, 0.01, 0.0])  # m


@pytest.fixture()
def world_and_cube():
    task = load_task(catalog.find("tasks", "pick_place"))
    with World(task) as world:
        cube = world.add_body(task.config.pick_place.object)
        yield world, cube


def _top_down(center, width=0.04) -> Grasp:
    """A grasp from above: approach −z, closing along x (GraspNet frame columns x, y, z)."""
    R = np.column_stack([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    return Grasp(np.asarray(center, float), R, width)


def _color_pixels(frame: np.ndarray, color, tol: int = 30, legend: bool = False) -> np.ndarray:
    """(row, col) of pixels within ``tol`` of ``color``, outside the legend (bottom-left) unless
    ``legend``."""
    hits = np.argwhere(np.abs(frame.astype(int) - np.asarray(color)).max(axis=2) <= tol)
    if legend:
        return hits
    h = frame.shape[0]
    return hits[~((hits[:, 0] > h - 50) & (hits[:, 1] < 160))]


def test_outlines_follow_the_object(world_and_cube, tmp_path):
    world, cube = world_and_cube
    pos, _ = world.body_pose(cube)
    grasps = [_top_down(pos), _top_down(np.add(pos, SIDE))]
    rec = GraspRecorder(world, tmp_path / "g.png", camera=CAM, size=(320, 240), overlay=False)
    rec.show(grasps, obj=cube)
    before = rec.render()
    best0 = _color_pixels(before, BEST)
    assert len(best0) > 20 and len(_color_pixels(before, OTHER)) > 10
    # the outline sits where the grasp's own world polylines project
    px, _ = rec.project(np.vstack(grasp_polylines(grasps[0])))
    assert np.linalg.norm(best0.mean(axis=0)[::-1] - px.mean(axis=0)) < 15
    world.set_body_pose(cube, np.add(pos, LIFT), [0.0, 0.0, 0.0, 1.0])  # "lifted" 15 cm
    after = rec.render()
    best1 = _color_pixels(after, BEST)
    lifted = rec.project(np.add(np.vstack(grasp_polylines(grasps[0])), LIFT))[0]
    assert np.linalg.norm(best1.mean(axis=0)[::-1] - lifted.mean(axis=0)) < 15  # drawn on the lifted cube
    assert best1.mean(axis=0)[0] < best0.mean(axis=0)[0] - 20  # higher in the picture (rows grow down)


def test_without_an_object_outlines_stay_put(world_and_cube, tmp_path):
    world, cube = world_and_cube
    pos, _ = world.body_pose(cube)
    rec = GraspRecorder(world, tmp_path / "g.png", camera=CAM, size=(320, 240), overlay=False)
    rec.show([_top_down(pos)])
    before = _color_pixels(rec.render(), BEST).mean(axis=0)
    world.set_body_pose(cube, np.add(pos, LIFT), [0.0, 0.0, 0.0, 1.0])
    assert np.linalg.norm(_color_pixels(rec.render(), BEST).mean(axis=0) - before) < 3


def test_legend_names_best_and_others(world_and_cube, tmp_path):
    world, cube = world_and_cube
    pos, _ = world.body_pose(cube)
    rec = GraspRecorder(world, tmp_path / "g.png", camera=CAM, size=(320, 240), overlay=False)
    rec.show([_top_down(pos)] * 3, obj=cube)
    frame = rec.render()
    corner = frame[-50:, :120]  # the key in the bottom-left corner: white box with both colour swatches
    assert len(_color_pixels(corner, BEST, 10, True)) >= 10 and len(_color_pixels(corner, OTHER, 10, True)) >= 10
    assert (corner == 255).all(axis=2).mean() > 0.3
