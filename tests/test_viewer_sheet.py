"""``robocfg view --png``: frames computed on real robots, cameras that fit, the sheet drawn."""

import numpy as np
import pybullet as p
import pytest
from _cli import run_main
from PIL import Image

from robocfg.checks import load_robot
from robocfg.config import catalog
from robocfg.config.types import AXIS_INDEX
from robocfg.sim.record_camera import fit_camera, project
from robocfg.sim.still_scene import StillScene
from robocfg.viewer.overlay import AXIS_COLORS, PAD_COLOR
from robocfg.viewer.sheet import PANEL, scene_frames


@pytest.fixture(scope="module")
def panda_scene():
    with StillScene.of_robot(load_robot(catalog.find("robots", "panda"))) as scene:
        yield scene


def test_frames_follow_the_yaml_conventions(panda_scene):
    (frames,) = scene_frames(panda_scene, 0.1)
    arm = panda_scene.robots[0].arm()
    _base, ee, tcp, grasp = frames.triads
    assert np.allclose(ee.pose, arm.ee_pose())
    assert np.allclose(tcp.pose[:3, 3], arm.tcp_pose()[:3, 3])
    assert np.isclose(np.linalg.norm(frames.ee_axis.end - frames.ee_axis.start), arm.config.tcp_offset)
    # grasp x (approach) is the EE's ee_axis; world_R_ee = world_R_grasp · R_ee_graspnet
    assert np.allclose(grasp.pose[:3, 0], ee.pose[:3, AXIS_INDEX[arm.config.ee_axis]])
    assert np.allclose(grasp.pose[:3, :3] @ np.asarray(arm.config.R_ee_graspnet), ee.pose[:3, :3])
    # the TCP sits between the two (open) finger pads, which are max_width apart along grasp y
    centres = [pad.corners.mean(axis=0) for pad in frames.pads]
    assert len(centres) == 2
    assert np.linalg.norm((centres[0] + centres[1]) / 2 - tcp.pose[:3, 3]) < 0.01
    assert abs(abs(np.dot(centres[0] - centres[1], grasp.pose[:3, 1])) - 0.08) < 0.03


@pytest.mark.parametrize("direction", [(1, 0, 0.3), (0, -1, 0.3), (0, 0, 1), (-0.3, 0.5, 0.2)])
def test_fitted_camera_keeps_the_whole_box_in_the_picture(panda_scene, direction):
    lo, hi = panda_scene.aabb()
    cam = fit_camera(lo, hi, direction, margin=1.05)
    corners = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] for k in range(8)])
    px, front = project(corners, panda_scene.client, cam, PANEL)
    assert front.all()
    assert (px >= 0).all() and (px[:, 0] <= PANEL[0]).all() and (px[:, 1] <= PANEL[1]).all()
    # ... and fills it: some corner lies within 12 % of an edge
    margin_px = np.minimum.reduce([px[:, 0], PANEL[0] - px[:, 0], px[:, 1], PANEL[1] - px[:, 1]])
    assert margin_px.min() < 0.12 * PANEL[1]


def test_scene_teleports_the_first_arm_to_q():
    robot = load_robot(catalog.find("robots", "panda"))
    q = [0.3, -0.2, 0.1, -2.0, 0.2, 1.8, 0.5]
    with StillScene.of_robot(robot, q) as scene:
        arm = scene.robots[0].arm()
        assert np.allclose(arm.joint_positions(), q, atol=1e-9)
        g = robot.config.arms[0].gripper
        assert np.isclose(scene.robots[0].joint_positions(["panda_finger_joint1"])[0], g.open[0])
        assert np.isclose(scene.robots[0].joint_positions(["panda_finger_joint2"])[0], g.open[0])  # mimic follower
        assert p.getNumBodies(physicsClientId=scene.client) == 2  # ground + robot


def _has_color(img: np.ndarray, rgb, tol=8) -> int:
    return int(np.sum(np.all(np.abs(img.astype(int) - np.array(rgb)) <= tol, axis=-1)))


def test_view_png_cli_draws_frames_and_pads(tmp_path, capsys, monkeypatch):
    out = tmp_path / "panda.png"
    code, _stdout, stderr = run_main(["view", "panda", "--png", str(out)], capsys, monkeypatch)
    assert code == 0, stderr
    img = np.asarray(Image.open(out).convert("RGB"))
    assert img.shape[1] == 2 * PANEL[0] and img.shape[0] > 2 * PANEL[1]
    for color in (*AXIS_COLORS, PAD_COLOR):
        assert _has_color(img, color) > 50, color
    # another pose gives another picture
    moved = tmp_path / "moved.png"
    code, _, stderr = run_main(["view", "panda", "--png", str(moved), "--q", "0.8,-0.4,0,-2.0,0,1.6,0.8"],
                               capsys, monkeypatch)
    assert code == 0, stderr
    assert not np.array_equal(img, np.asarray(Image.open(moved).convert("RGB")))


def test_view_user_errors_exit_2(tmp_path, capsys, monkeypatch):
    code, _, err = run_main(["view", "pandaa", "--png", str(tmp_path / "x.png")], capsys, monkeypatch)
    assert code == 2 and "did you mean 'panda'" in err and "Traceback" not in err
    code, _, err = run_main(["view", "panda", "--png", str(tmp_path / "x.png"), "--q", "0.1,0.2"], capsys, monkeypatch)
    assert code == 2 and "--q" in err and "7 joints" in err
    assert not (tmp_path / "x.png").exists()


def test_view_task_shows_its_scenery(tmp_path, capsys, monkeypatch):
    out = tmp_path / "task.png"
    code, _, stderr = run_main(["view", "pick_place_kuka_kr210", "--png", str(out), "--collision"], capsys, monkeypatch)
    assert code == 0, stderr
    task = catalog.find("tasks", "pick_place_kuka_kr210")
    from robocfg.checks import load_task

    with StillScene.of_task(load_task(task)) as scene:
        lo, _hi = scene.aabb()
        robot_lo = min(p.getAABB(scene.robots[0].body_id, li, physicsClientId=scene.client)[0][2]
                       for li in scene.robots[0].link_index.values())
    assert scene.scenery, "the pedestal is part of the picture"
    assert lo[2] < robot_lo - 0.1  # the box (so the cameras) includes the pedestal below the robot
