"""--camera / --size / --fps of robocfg run: parsed with clear errors, applied by the recorder."""

import pytest
from _cli import run_main
from PIL import Image

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.sim.record import Recorder
from robocfg.sim.record_settings import OrbitCamera, RecordSettings, parse_camera, parse_size
from robocfg.sim.world import World


def test_parse_camera_and_size():
    cam = parse_camera("30,-35,1.2,0.5,0,0.1")
    assert cam == OrbitCamera(30.0, -35.0, 1.2, (0.5, 0.0, 0.1))
    assert parse_size("480x360") == (480, 360) and parse_size("200X150") == (200, 150)
    for bad, says in (("30,-35,1.2", "six numbers"), ("a,b,c,d,e,f", "six numbers"), ("0,0,-1,0,0,0", "distance")):
        with pytest.raises(ValueError, match=says):
            parse_camera(bad)
    for bad in ("480", "480x", "10x10", "4000x300"):
        with pytest.raises(ValueError):
            parse_size(bad)


def test_recorder_applies_the_settings(tmp_path):
    with World(load_task(catalog.find("tasks", "gripper"))) as world:
        s = RecordSettings(camera=OrbitCamera(10.0, -20.0, 0.9, (0.4, 0.0, 0.2)), size=(200, 150), fps=5.0)
        rec = Recorder(world, tmp_path / "x.gif", fps=15.0, settings=s)
        assert rec.size == (200, 150) and rec.fps == 5.0
        assert rec.camera.target == (0.4, 0.0, 0.2) and rec.camera.yaw_deg == 10.0 and rec.camera.distance == 0.9
        assert rec.render().shape == (150, 200, 3)
        fitted = Recorder(world, tmp_path / "y.gif", settings=RecordSettings(size=(300, 100)))
        assert fitted.camera.eye is not None and fitted.size == (300, 100)  # still fitted, to the new aspect


def test_cli_records_at_the_given_size(tmp_path, capsys, monkeypatch):
    out = tmp_path / "last.png"
    code, _, err = run_main(["run", "gripper", "-q", "--record", str(out), "--size", "200x150",
                             "--camera", "60,-25,0.6,0.45,0,0.3"], capsys, monkeypatch)
    assert code == 0, err
    assert Image.open(out).size == (200, 150)


@pytest.mark.parametrize(("args", "says"), [
    (["--size", "480x360"], "add --record PATH"),
    (["--record", "x.gif", "--size", "480"], "WxH"),
    (["--record", "x.gif", "--camera", "1,2,3"], "six numbers"),
])
def test_cli_rejects_bad_recording_options(args, says, tmp_path, capsys, monkeypatch):
    code, _, err = run_main(["run", "gripper", "-q", *args], capsys, monkeypatch, cwd=tmp_path)
    assert code == 2 and says in " ".join(err.split()) and "Traceback" not in err
    assert not (tmp_path / "x.gif").exists()
