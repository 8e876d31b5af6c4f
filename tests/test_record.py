"""Recorder: a camera fitted to the scene (KR210 on its pedestal included), overlays, MP4, GIF,
and the contact sheet, on real worlds."""

import av
import numpy as np
import pybullet as p
import pytest
from PIL import Image

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.sim.record import Recorder
from robocfg.sim.record_camera import scene_camera
from robocfg.sim.record_overlay import FAIL_COLOR
from robocfg.sim.world import World


@pytest.fixture(scope="module")
def kr210_world():
    with World(load_task(catalog.find("tasks", "pick_place_kuka_kr210"))) as world:
        yield world


def test_fitted_camera_shows_the_kr210_and_its_pedestal(kr210_world):
    size = (320, 240)
    cam = scene_camera(kr210_world, size)
    rec = Recorder(kr210_world, "unused.png", size=size, camera=cam)
    for name in ("pedestal", kr210_world.robot.name):
        bid = kr210_world.body_id(name)
        for li in range(-1, p.getNumJoints(bid, physicsClientId=kr210_world.client)):
            lo, hi = p.getAABB(bid, li, physicsClientId=kr210_world.client)
            corners = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] for k in range(8)])
            px, front = rec.project(corners)
            assert front.all()
            assert (px[:, 0] >= -1).all() and (px[:, 0] <= size[0] + 1).all(), (name, li)
            assert (px[:, 1] >= -1).all() and (px[:, 1] <= size[1] + 1).all(), (name, li)
    # and the robot is not a speck: its base-to-flange height spans a good part of the picture
    img = rec.render()
    assert (np.abs(img.astype(int) - img[0, 0]).sum(axis=-1) > 60).mean() > 0.1


def test_default_camera_includes_the_place_target(kr210_world):
    rec = Recorder(kr210_world, "unused.png")
    assert rec.markers and rec.markers[0].label == "place target"
    px, front = rec.project(np.array([rec.markers[0].position]))
    assert front.all() and 0 <= px[0, 0] <= 320 and 0 <= px[0, 1] <= 240


def test_mp4_gif_and_sheet(tmp_path, kr210_world):
    state = kr210_world.snapshot()
    outs = {}
    for name in ("run.mp4", "run.gif", "run_sheet.png"):
        kr210_world.restore(state)
        rec = Recorder(kr210_world, tmp_path / name, fps=20.0)
        for phase in ("approach", "grasp", "lift"):
            rec.set_phase(phase)
            for _ in range(12):  # 0.05 s per phase at 240 Hz → one frame per phase at 20 fps
                kr210_world.step()
                rec.maybe_capture()
        rec.finish(False, "lift: object slipped")
        outs[name] = (rec.save(), len(rec.frames))
    path, n = outs["run.mp4"]
    with av.open(str(path)) as c:
        stream = c.streams.video[0]
        frames = [f.to_ndarray(format="rgb24") for f in c.decode(stream)]
    assert stream.codec_context.name == "h264" and (stream.width, stream.height) == (320, 240)
    assert len(frames) == n + 1  # the last frame is held once more
    # the failure banner (red) is on the last frame, not the first
    red = np.array(FAIL_COLOR)
    assert (np.abs(frames[-1].astype(int) - red).sum(axis=-1) < 60).sum() > 100
    assert (np.abs(frames[0].astype(int) - red).sum(axis=-1) < 60).sum() < 20
    gif = Image.open(outs["run.gif"][0])
    assert gif.n_frames == outs["run.gif"][1]
    gif.seek(gif.n_frames - 1)
    assert gif.info["duration"] >= 1000  # the result stays up (Pillow merges the held copies)
    sheet = Image.open(outs["run_sheet.png"][0])
    assert sheet.width == 4 * 320  # approach, grasp, lift and the last frame, side by side


def test_overlay_writes_time_and_phase(kr210_world):
    rec = Recorder(kr210_world, "unused.gif")
    raw = rec.render()
    rec.set_phase("approach")
    rec.capture()
    top = rec.frames[-1][:14].astype(int)
    assert np.abs(top - raw[:14]).sum() > 0
    assert rec.infos[-1].phase == "approach" and rec.infos[-1].t == pytest.approx(kr210_world.t)
    plain = Recorder(kr210_world, "unused.gif", overlay=False)
    plain.capture()
    assert np.array_equal(plain.frames[-1], plain.render())


def test_unknown_suffix_is_refused(kr210_world):
    from robocfg.errors import RobocfgError

    with pytest.raises(RobocfgError, match=r"\.gif, \.mp4 or \.png"):
        Recorder(kr210_world, "x.avi")


def test_gripper_and_grasp_recordings_name_their_phases_and_outcome(tmp_path, monkeypatch):
    from robocfg.engine import EpisodeObserver, RunOptions, run
    from robocfg.runners.gripper import run_gripper

    seen: list[str] = []
    monkeypatch.setattr(Recorder, "set_phase", lambda self, name: seen.append(name))
    res = run_gripper(load_task(catalog.find("tasks", "gripper")), record=tmp_path / "g_sheet.png")
    assert res.success and seen[:2] == ["close", "open"] and {"grasp", "hold", "release"} <= set(seen)

    class Spy(EpisodeObserver):
        def __init__(self):
            self.phases, self.outcome = [], None

        def set_phase(self, name):
            self.phases.append(name)

        def finish(self, success, reason=""):
            self.outcome = (success, reason)

    spy = Spy()
    run(load_task(catalog.find("tasks", "grasp")), RunOptions(seed=0, recorder=lambda world: spy))
    assert spy.phases[0] == "plan" and {"approach", "grasp", "lift"} <= set(spy.phases)
    assert spy.outcome == (True, "")  # the session reports the outcome to the recorder


def test_default_camera_faces_the_work_area_of_a_kr210(tmp_path):
    """The KR210's object and place target lie behind it from the default direction: the fitted
    camera turns so both are in sight, not hidden behind the pedestal."""
    task = load_task(catalog.find("tasks", "pick_place_kuka_kr210"))
    with World(task) as world:
        obj = task.config.pick_place.object
        world.add_body(obj)
        rec = Recorder(world, tmp_path / "unused.png", overlay=False)
        img = rec.render().astype(int)
        color = (np.asarray(obj.color[:3]) * 255).astype(int)
        box = np.abs(img - color).max(axis=2) < 60  # lit faces stay near the box's colour
        assert box.mean() > 0.003, "the object is in sight"
        px, front = rec.project(np.array([obj.position]))
        row, col = int(px[0, 1]), int(px[0, 0])
        assert front.all() and box[max(0, row - 8):row + 8, max(0, col - 8):col + 8].any()  # where it is
