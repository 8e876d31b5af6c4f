"""The browser viewer for real: a viser server on a free port, opened in headless Chromium
(Debian's ``chromium``, driven by playwright; ``.ci/run`` installs it), a slider moved from the
page, the gizmo followed by IK, and a YAML saved broken and fixed again."""

import os
import shutil
import socket
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from robocfg.config import catalog
from robocfg.viewer.browser import BrowserViewer
from robocfg.viewer.server import watch
from robocfg.viewer.source import ViewSource, find_source

CHROMIUM = Path("/usr/bin/chromium")
DOCS = Path(__file__).resolve().parent.parent / "docs"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait(cond, timeout: float = 60.0, what: str = "condition") -> None:
    end = time.monotonic() + timeout
    while not cond():
        if time.monotonic() > end:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.1)


def _scene_pixels(page) -> np.ndarray:
    """Grey pixels of the 3-D view left of the control panel (the page's screenshot)."""
    from io import BytesIO

    from PIL import Image

    img = Image.open(BytesIO(page.screenshot(clip={"x": 0, "y": 160, "width": 900, "height": 600})))
    return np.asarray(img.convert("L"), dtype=float)


@pytest.fixture
def viewer():
    v = BrowserViewer(find_source("panda"), port=_free_port())
    yield v
    v.stop()


@pytest.fixture(scope="module")
def browser():
    if not CHROMIUM.exists():
        pytest.skip("Debian's chromium is not installed (/usr/bin/chromium); .ci/run installs it")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=str(CHROMIUM), args=["--use-gl=swiftshader", "--enable-unsafe-swiftshader"])
        yield b
        b.close()


def test_viewer_binds_localhost_and_holds_robot_and_frames(viewer):
    assert viewer.server.get_host() == "127.0.0.1"
    names = viewer.scene_names()
    assert any(n.endswith("/panda_hand") for n in names), "robot links are scene nodes"
    assert any(n.endswith("/collision") for n in names), "collision meshes are loaded (hidden until toggled)"
    labels = [n for n in names if n.endswith("/label")]
    assert len(labels) == 4  # base, ee_link, TCP, grasp
    assert "/target" in names


def test_gizmo_moves_the_arm_by_ik(viewer):
    target = np.array([0.45, 0.15, 0.35])
    viewer.target.position = tuple(target)
    viewer.follow_target()
    assert viewer.ik_status.startswith("converged")
    tcp = viewer.frames[0].tcp()
    assert np.linalg.norm(tcp - target) < 1e-3
    # the drawn TCP comes from the URDF FK of the joint values IK returned, not from the gizmo
    arm = viewer.robots[0]
    assert np.allclose(arm.link_pose("panda_hand")[:3, 3], viewer.frames[0].ee_axis.start)


def test_page_shows_robot_and_slider_moves_a_link(viewer, browser, tmp_path):
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.set_default_timeout(120_000)  # software WebGL on a busy 2-core machine is slow
    try:
        page.goto(viewer.url)
        _wait(lambda: len(viewer.server.get_clients()) == 1, what="the page to connect")
        page.wait_for_selector("canvas", timeout=60000)
        page.get_by_text("panda_joint1").first.wait_for(timeout=60000)  # the sliders arrived
        time.sleep(2.0)  # let the client load the meshes and draw
        before = _scene_pixels(page)
        assert before.std() > 10, "the 3-D view shows something"
        hand0 = viewer.robots[0].link_pose("panda_hand")[:3, 3].copy()
        slider = page.get_by_role("slider").first  # panda_joint1
        slider.focus()
        page.keyboard.press("End")
        upper = viewer.sliders["panda_joint1"].max
        _wait(lambda: abs(viewer.robots[0].q["panda_joint1"] - upper) < 1e-6, what="the slider update")
        hand1 = viewer.robots[0].link_pose("panda_hand")[:3, 3]
        assert np.linalg.norm(hand1 - hand0) > 0.1
        assert np.isclose(np.linalg.norm(hand1[:2]), np.linalg.norm(hand0[:2]))  # a turn about the base z axis
        _wait(lambda: np.abs(_scene_pixels(page).astype(int) - before).mean() > 0.5, what="the page to redraw")
        for close in page.locator("button.mantine-Notification-closeButton").all():
            close.click()
        time.sleep(1.5)  # the notification fades out, the labels settle
        shot = page.screenshot(path=str(tmp_path / "viewer-panda.png"))
        assert len(shot) > 10_000
        if os.environ.get("ROBOCFG_UPDATE_DOCS"):  # refresh docs/viewer-panda.png (kept out of plain runs: no churn)
            (DOCS / "viewer-panda.png").write_bytes(shot)
    finally:
        page.close()


def test_saving_a_broken_yaml_shows_its_errors_in_the_page(tmp_path, browser):
    src = catalog.find("robots", "panda")
    path = tmp_path / "my_panda.yaml"
    shutil.copy(src, path)
    v = BrowserViewer(ViewSource("robot", path), port=_free_port())
    stop = threading.Event()
    watcher = threading.Thread(target=watch, args=(v, 0.05, stop.is_set), daemon=True)
    watcher.start()
    page = browser.new_page()
    page.set_default_timeout(120_000)  # software WebGL on a busy 2-core machine is slow
    try:
        page.goto(v.url)
        _wait(lambda: len(v.server.get_clients()) == 1, what="the page to connect")
        text = path.read_text()
        path.write_text(text.replace("ee_link: panda_hand", "ee_link: panda_hnd"))
        _wait(lambda: bool(v.errors), what="the reload with errors")
        line = next(i for i, s in enumerate(text.splitlines(), 1) if "ee_link: panda_hand" in s)
        assert v.errors[0].startswith(f"{path}:{line}:")
        assert "did you mean 'panda_hand'" in v.errors[0]
        page.get_by_text("is invalid").first.wait_for(timeout=60000)
        assert page.get_by_text("panda_hnd").count() >= 1
        path.write_text(text)
        _wait(lambda: not v.errors and v.robots, what="the reload after the fix")
    finally:
        stop.set()
        watcher.join(5)
        page.close()
        v.stop()


def test_task_cameras_are_frusta_and_the_wrist_one_follows_the_arm():
    v = BrowserViewer(find_source("pick_place"), port=_free_port())
    try:
        names = v.scene_names()
        assert {"/cameras/scene", "/cameras/wrist"} <= set(names)
        by_name = {c.camera.name: c for c in v.cameras}
        scene, wrist = by_name["scene"], by_name["wrist"]
        cam = scene.camera
        # the scene camera sits at its position, optical axis (z) towards look_at, image y down
        R = np.asarray(_quat_matrix(scene.handle.wxyz))
        assert np.allclose(scene.handle.position, cam.position)
        axis = np.subtract(cam.look_at, cam.position)
        assert np.allclose(R[:, 2], axis / np.linalg.norm(axis), atol=1e-6)
        assert R[:, 1] @ np.asarray(cam.up) < 0
        fixed, moving = np.array(scene.handle.position), np.array(wrist.handle.position)
        ee = v.robots[0].link_pose(v.robots[0].checked.config.arms[0].ee_link)
        assert np.allclose(moving, ee[:3, :3] @ np.asarray(wrist.camera.position) + ee[:3, 3], atol=1e-6)
        v.set_joint("panda_joint1", 0.8)
        assert np.linalg.norm(np.array(wrist.handle.position) - moving) > 0.05  # the wrist camera went along
        assert np.allclose(scene.handle.position, fixed)  # the scene camera did not
    finally:
        v.stop()


def _quat_matrix(wxyz) -> np.ndarray:
    from robocfg.geometry import quat_to_matrix

    w, x, y, z = wxyz
    return quat_to_matrix([x, y, z, w])


@pytest.fixture(scope="module")
def pick_place_playback():
    from robocfg.checks import load_task
    from robocfg.viewer.playback import record_run

    return record_run(load_task(catalog.find("tasks", "pick_place")), seed=0)


def test_a_recorded_pick_place_plays_back_in_the_page(pick_place_playback):
    pb = pick_place_playback
    assert pb.success is True and pb.duration > 3.0
    names = [name for name, _ in pb.phases()]
    assert {"grasp", "lift", "place"} & set(names) and names.index("lift") > names.index("grasp")
    v = BrowserViewer(find_source("pick_place"), port=_free_port(), playback=pb)
    try:
        obj = v.source.load().config.pick_place.object.name
        handle = v.scenery[obj]
        v.show_time(0.0)
        z0, q0 = handle.position[2], dict(v.robots[0].q)
        lift = dict(pb.phases())["lift"]
        t_lifted = next(f.t for f in pb.frames if f.t > lift and f.bodies[obj][0][2] > z0 + 0.03)
        v.time_slider.value = t_lifted  # as the page's slider does
        _wait(lambda: handle.position[2] > z0 + 0.03, timeout=10, what="the object to rise with the slider")
        assert np.allclose(handle.position, pb.at(t_lifted).bodies[obj][0])
        assert any(abs(v.robots[0].q[j] - q0[j]) > 0.05 for j in q0)  # the arm moved too
        assert v._phase_text.content.endswith(f"phase: {pb.at(t_lifted).phase}")
        assert pb.at(t_lifted).phase not in ("", "pre_grasp", "approach", "grasp")  # it is past the grasp
        v.toggle_play()  # plays from there to the end in real time, then stops
        _wait(lambda: not v._playing.is_set(), timeout=30, what="the playback to end")
        assert v.time_slider.value == pytest.approx(pb.duration)
        final = pb.frames[-1].bodies[obj][0]
        assert np.allclose(handle.position, final)
    finally:
        v.stop()


@pytest.mark.parametrize(("target", "says"), [("panda", "is a robot YAML"), ("pick_place", "is a 'pick_place' task, not 'grasp'")])
def test_run_option_names_what_cannot_be_played(target, says, capsys, monkeypatch):
    from _cli import run_main

    code, _, err = run_main(["view", target, "--run", "grasp"], capsys, monkeypatch)
    assert code == 2 and says in " ".join(err.split()) and "Traceback" not in err
