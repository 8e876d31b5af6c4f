"""--dataset on the kinds beyond pick-place: pick-place-many (several objects in the environment
state, replayed through its runner, the same dataset on 1 and 2 workers)."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import yaml
from _cli import ROOT, run_main
from _parallel import files_of, run_json

from robocfg.datasets.replay import replay_episode


def _two_objects(tmp) -> str:
    """The shipped pick-place-many task with its first two objects only (a quicker episode)."""
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place_many.yaml").read_text())
    doc["pick_place_many"]["objects"] = doc["pick_place_many"]["objects"][:2]
    path = tmp / "two_objects.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return str(path)


def test_pick_place_many_records_every_object_and_replays(tmp_path, capsys, monkeypatch):
    task = _two_objects(tmp_path)
    common = ["run", "pick-place-many", task, "-n", "2", "--dataset-fps", "10", "--keep", "all"]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    two = run_json([*common, "--workers", "2", "--dataset", str(tmp_path / "two")], tmp_path, "two", capsys, monkeypatch)
    assert one == two and [e["success"] for e in one["episodes"]] == [True, True]
    assert files_of(tmp_path / "one") == files_of(tmp_path / "two")

    root = tmp_path / "one"
    info = json.loads((root / "meta/info.json").read_text())
    names = info["features"]["observation.environment_state"]["names"]
    assert names[:3] == ["object.red.x", "object.red.y", "object.red.z"] and names[7] == "object.green.x"
    assert len(names) == 14 and "withdraw" in info["robocfg"]["phases"]
    tasks = pq.read_table(root / "meta/tasks.parquet").to_pydict()["__index_level_0__"]
    assert tasks == ["put the red box and the green box into bin_b"]
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    env = np.asarray(data["observation.environment_state"].to_pylist())
    ep0 = env[data["episode_index"].to_numpy() == 0]
    # each object's own track: red and green start 12 cm apart in x and both end in bin_b (y > 0)
    assert abs((ep0[0, 7] - ep0[0, 0]) - 0.12) < 0.03 and ep0[-1, 1] > 0.1 and ep0[-1, 8] > 0.1
    final = [ep["objects"] for ep in one["episodes"]][1]

    r = replay_episode(root, 1)
    assert r.matches and r.replayed_reason == "2 objects placed"
    assert np.allclose(np.reshape(r.replayed_object, (2, 3)), [o["final"] for o in final], atol=1e-3)
    # the gripper never closing: no object leaves bin_a, and replay says so
    path = root / "data/chunk-000/file-000.parquet"
    act = np.asarray(data["action"].to_pylist(), np.float32)
    act[:, -1] = 1.0
    col = pa.FixedSizeListArray.from_arrays(pa.array(act.reshape(-1)), act.shape[1])
    pq.write_table(data.set_column(data.schema.get_field_index("action"), "action", col), path)
    r = replay_episode(root, 1)
    assert not r.matches and not r.replayed_success and r.replayed_reason.startswith("red: place")


def _moving_obstacle_task(tmp) -> str:
    """A static target and a ball flying onto it (the arm gives way: not reached), 2.2 s."""
    ball = {"name": "drone", "shape": "sphere", "size": [0.04],
            "motion": {"type": "waypoints", "waypoints": [[0.45, 0.3, 0.35], [0.45, 0.03, 0.35]],
                       "waypoint_times": [0.3, 2.0]}}
    doc = {"schema_version": 1, "task": "follow_target", "robots": [{"robot": "panda"}], "scene": {"ground": True},
           "sim": {"timestep": 1 / 240},
           "follow_target": {"motion": {"type": "static", "center": [0.45, 0.0, 0.35]}, "duration": 2.2,
                             "settle_time": 1.0, "with_obstacle": True, "obstacles": [ball]}}
    path = tmp / "moving_obstacle.yaml"
    path.write_text(yaml.safe_dump(doc))
    return str(path)


def test_follow_target_records_the_controller_and_replays_with_the_moving_obstacle(tmp_path, capsys, monkeypatch):
    """The closed-loop controller's joint targets are the actions; replay re-moves the ball at the
    same control periods: the same outcome, TCP end and closest approach to the ball."""
    task, root = _moving_obstacle_task(tmp_path), tmp_path / "ft"
    report = run_json(["run", "follow-target", task, "--dataset", str(root), "--keep", "all", "--dataset-format",
                       "hdf5"], tmp_path, "ft", capsys, monkeypatch)
    assert not report["reached"] and report["min_clearance_mm"] > 10.0 and report["contacts"] == 0
    import h5py

    with h5py.File(root / "data.hdf5", "r") as f:
        demo = f["data/demo_0"]
        a = demo.attrs
        assert not a["success"] and a["failed_phase"] == "track" and "blocked" in a["reason"]
        assert a["language"] == "reach the target with the tool, avoiding the obstacle"
        n = a["num_samples"]
        assert n == a["physics_steps"] // 12 + 1 and demo["actions"].shape == (n, 8)
        assert set(np.unique(demo["phase"][()])) == {0, 1}  # settle, then track
        act, q = demo["actions"][()], demo["obs/robot_state"][()][:, :7]
        assert np.all(act[:, -1] == 1.0) and np.abs(act[-1, :7] - q[-1]).max() < 0.01
    r = replay_episode(root, 0)
    assert r.matches and not r.replayed_success and r.distance < 1e-6
    assert f"min clearance {report['min_clearance_mm']:.2f} mm, 0 contacts" in r.replayed_reason
    with h5py.File(root / "data.hdf5", "r+") as f:
        f["data/demo_0/actions"][-10:, 1] += 0.05  # the shoulder's last targets moved by 0.05 rad
    r = replay_episode(root, 0)
    assert not r.matches and r.distance > 0.01


def test_follow_target_dataset_with_gui_is_refused(tmp_path, capsys, monkeypatch):
    code, _, err = run_main(["run", "follow-target", "--gui", "--dataset", str(tmp_path / "x")], capsys, monkeypatch)
    assert code == 2 and "--dataset with --gui" in err and not (tmp_path / "x").exists()
