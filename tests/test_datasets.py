"""Datasets recorded from real pick-place runs: LeRobot v3.0 conformance (pyarrow + PyAV only),
robomimic HDF5 layout, replay from the recorded actions, CLI errors."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import av
import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import yaml
from _cli import ROOT, run_main
from _lerobot_conformance import check_lerobot

from robocfg.checks import load_task
from robocfg.datasets.language import pick_place_instruction
from robocfg.datasets.replay import replay_episode
from robocfg.datasets.sink import DatasetSink
from robocfg.runners.pick_place import run_pick_place

FPS = 10  # divides the 240 Hz physics rate; fewer rendered frames keep the test quick


def _task_file(tmp: Path, depth: bool) -> Path:
    """The shipped pick-place task with 32x32 cameras (a wrist camera with depth when asked)."""
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    for cam in doc["cameras"]:
        cam["width"] = cam["height"] = 32
    doc["cameras"][1]["depth"] = depth
    path = tmp / "pick_place_small_cams.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _record(tmp: Path, fmt: str, episodes: int, depth: bool = False):
    task = load_task(_task_file(tmp, depth))
    root = tmp / f"ds_{fmt}"
    sink = DatasetSink(root, fmt, task, fps=FPS, keep="all", language=pick_place_instruction(task.config.pick_place),
                       extra_info={"task_path": str(task.path), "seed": 3, "arm": None, "robot_override": None})
    report, _ = run_pick_place(task, episodes, seed=3, sink=sink)
    sink.close()
    return root, report


@pytest.fixture(scope="module")
def lerobot_ds(tmp_path_factory):
    return _record(tmp_path_factory.mktemp("lr"), "lerobot", 2, depth=True)


def test_lerobot_layout_dtypes_and_index_ranges(lerobot_ds):
    root, report = lerobot_ds
    assert [e.success for e in report.episodes] == [True, True]  # recording keeps pick-place working
    for rel in ("meta/info.json", "meta/stats.json", "meta/tasks.parquet", "meta/episodes/chunk-000/file-000.parquet",
                "data/chunk-000/file-000.parquet", "videos/observation.images.scene/chunk-000/file-000.mp4",
                "videos/observation.images.wrist/chunk-000/file-000.mp4"):
        assert (root / rel).is_file(), rel
    info = json.loads((root / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0" and info["fps"] == FPS and info["total_episodes"] == 2
    feats = info["features"]
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    assert data.num_rows == info["total_frames"]
    for key in ("observation.state", "observation.environment_state", "action"):
        t = data.schema.field(key).type
        assert pa.types.is_fixed_size_list(t) and t.value_type == pa.float32()
        assert t.list_size == feats[key]["shape"][0] == len(feats[key]["names"])
    for key in ("frame_index", "episode_index", "index", "task_index", "phase_index"):
        assert data.schema.field(key).type == pa.int64()
    assert data.schema.field("timestamp").type == pa.float32()
    assert np.array_equal(data["index"].to_numpy(), np.arange(data.num_rows))
    np.testing.assert_allclose(data["timestamp"].to_numpy(), data["frame_index"].to_numpy() / FPS, atol=1e-6)
    eps = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    ep_col = data["episode_index"].to_numpy()
    frame_col = data["frame_index"].to_numpy()
    start = 0
    for k, e in enumerate(eps):
        assert e["episode_index"] == k and e["dataset_from_index"] == start
        assert e["dataset_to_index"] - start == e["length"] == int(np.sum(ep_col == k))
        assert np.array_equal(frame_col[start:e["dataset_to_index"]], np.arange(e["length"]))
        # one frame every 1/fps s of simulated time, frame 0 included, up to the last physics step
        assert e["length"] == e["physics_steps"] // (240 // FPS) + 1
        assert e["tasks"] == ["pick the red cube and place it on the target"]
        start = e["dataset_to_index"]
    # the actions really are joint targets the arm followed: the last one is where the arm is
    act = np.asarray(data["action"].to_pylist())[:, :7]
    state = np.asarray(data["observation.state"].to_pylist())[:, :7]
    assert np.max(np.abs(act[eps[0]["length"] - 1] - state[eps[0]["length"] - 1])) < 0.02
    # the TCP (base frame = world here) sits on the cube while grasping; quaternions are unit
    names = json.loads((root / "meta/info.json").read_text())["features"]["observation.state"]["names"]
    full = np.asarray(data["observation.state"].to_pylist())
    tcp = full[:, names.index("tcp.x"):names.index("tcp.z") + 1]
    quat = full[:, names.index("tcp.qx"):names.index("tcp.qw") + 1]
    obj = np.asarray(data["observation.environment_state"].to_pylist())
    grasping = data["phase_index"].to_numpy() == info["robocfg"]["phases"].index("grasp")
    assert grasping.any()
    assert np.max(np.linalg.norm(tcp[grasping] - obj[grasping, :3], axis=1)) < 0.02
    np.testing.assert_allclose(np.linalg.norm(quat, axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(obj[:, 3:], axis=1), 1.0, atol=1e-5)
    phases = data["phase_index"].to_numpy()
    assert set(info["robocfg"]["phases"][i] for i in np.unique(phases)) >= {"approach", "grasp", "transport", "retract"}


def test_lerobot_conformance_of_a_recorded_dataset(lerobot_ds):
    """The shared conformance check (pyarrow + PyAV; multi-file datasets: test_datasets_rollover);
    two short episodes stay one file per series at lerobot's default limits."""
    root, _ = lerobot_ds
    seen = check_lerobot(root)
    assert all(len(files) == 1 for files in seen.files.values()) and len(seen.files) == 4
    info = json.loads((root / "meta/info.json").read_text())
    assert (info["chunks_size"], info["data_files_size_in_mb"], info["video_files_size_in_mb"]) == (1000, 100, 200)


def test_lerobot_depth_is_a_float32_height_by_width_feature_in_metres(lerobot_ds):
    """The wrist camera's depth: an (H, W) float32 feature in the data parquet (nested fixed-size
    lists: what LeRobotDataset reads as a datasets.Array2D), metres, stats over all pixels."""
    root, _ = lerobot_ds
    info = json.loads((root / "meta/info.json").read_text())
    key = "observation.depth.wrist"
    assert info["features"][key] == {"dtype": "float32", "shape": [32, 32], "names": ["height", "width"]}
    assert "observation.depth.scene" not in info["features"] and "metres" in info["robocfg"]["depth"]
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    t = data.schema.field(key).type
    assert pa.types.is_fixed_size_list(t) and t.list_size == 32
    assert pa.types.is_fixed_size_list(t.value_type) and t.value_type.list_size == 32
    assert t.value_type.value_type == pa.float32()
    depth = data[key].combine_chunks().flatten().flatten().to_numpy().reshape(-1, 32, 32)
    assert depth.shape[0] == data.num_rows
    # metres in front of the wrist: the cube under the gripper while grasping is a few cm away
    grasping = data["phase_index"].to_numpy() == info["robocfg"]["phases"].index("grasp")
    assert 0.0 < float(depth[grasping].min()) < 0.2 and float(depth.max()) < 5.0
    stats = json.loads((root / "meta/stats.json").read_text())[key]
    assert stats["min"] == [[pytest.approx(float(depth.min()))]] and stats["max"] == [[pytest.approx(float(depth.max()))]]
    assert stats["mean"][0][0] == pytest.approx(float(depth.astype(np.float64).mean()), rel=1e-9)
    assert stats["q50"][0][0] == pytest.approx(float(np.median(depth)), abs=1e-3)  # 1 mm bins
    assert stats["count"] == [data.num_rows]


def test_lerobot_videos_have_one_frame_per_row_at_index_over_fps(lerobot_ds):
    root, _ = lerobot_ds
    info = json.loads((root / "meta/info.json").read_text())
    eps = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
    for cam in ("scene", "wrist"):
        key = f"observation.images.{cam}"
        assert info["features"][key]["dtype"] == "video" and info["features"][key]["shape"] == [32, 32, 3]
        with av.open(str(root / f"videos/{key}/chunk-000/file-000.mp4")) as c:
            frames = list(c.decode(video=0))
        assert len(frames) == info["total_frames"]
        np.testing.assert_allclose([float(f.time) for f in frames], np.arange(len(frames)) / FPS, atol=1e-6)
        assert frames[0].to_ndarray(format="rgb24").shape == (32, 32, 3)
        for e in eps:
            assert e[f"videos/{key}/from_timestamp"] == pytest.approx(e["dataset_from_index"] / FPS)
            assert e[f"videos/{key}/to_timestamp"] == pytest.approx(e["dataset_to_index"] / FPS)


def test_lerobot_stats_and_tasks(lerobot_ds):
    root, _ = lerobot_ds
    stats = json.loads((root / "meta/stats.json").read_text())
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    state = np.asarray(data["observation.state"].to_pylist())
    np.testing.assert_allclose(stats["observation.state"]["mean"], state.mean(0), rtol=1e-5, atol=1e-6)
    assert stats["observation.state"]["count"] == [data.num_rows]
    for k in ("min", "max", "mean", "std", "q01", "q50", "q99"):
        assert np.asarray(stats["observation.images.scene"][k]).shape == (3, 1, 1)
    tasks = pq.read_table(root / "meta/tasks.parquet")
    meta = json.loads(tasks.schema.metadata[b"pandas"])
    assert meta["index_columns"] == ["__index_level_0__"]
    assert tasks.to_pydict() == {"task_index": [0], "__index_level_0__": ["pick the red cube and place it on the target"]}


def test_replay_matches_and_tampered_actions_do_not(lerobot_ds, tmp_path):
    root, report = lerobot_ds
    r = replay_episode(root, 1)
    assert r.matches and r.replayed_success and r.distance < 1e-3
    assert r.replayed_object == pytest.approx(report.episodes[1].object_final, abs=1e-3)
    # never closing the gripper: the same episode cannot place the cube, and replay says so
    bad = tmp_path / "bad"
    shutil.copytree(root, bad)
    path = bad / "data/chunk-000/file-000.parquet"
    t = pq.read_table(path)
    act = np.asarray(t["action"].to_pylist(), np.float32)
    act[:, -1] = 1.0
    col = pa.FixedSizeListArray.from_arrays(pa.array(act.reshape(-1)), act.shape[1])
    pq.write_table(t.set_column(t.schema.get_field_index("action"), "action", col), path)
    r = replay_episode(bad, 1)
    assert not r.matches and not r.replayed_success


def test_hdf5_robomimic_layout(tmp_path):
    root, report = _record(tmp_path, "hdf5", 1, depth=True)
    with h5py.File(root / "data.hdf5", "r") as f:
        demo = f["data/demo_0"]
        n = demo.attrs["num_samples"]
        assert f["data"].attrs["total"] == n
        env = json.loads(f["data"].attrs["env_args"])
        assert env["env_kwargs"]["robot"] == "panda" and env["env_kwargs"]["fps"] == FPS
        assert demo["actions"].shape == (n, 8) and demo["actions"].dtype == np.float32
        assert demo["obs/robot_state"].shape[0] == n and demo["obs/object_state"].shape == (n, 7)
        assert demo["obs/scene_image"].shape == (n, 32, 32, 3) and demo["obs/scene_image"].dtype == np.uint8
        depth = demo["obs/wrist_depth"][()]
        assert depth.shape == (n, 32, 32) and 0.0 < float(depth.min()) < 1.0  # metres in front of the wrist
        assert demo["states"].shape == (n, demo["obs/robot_state"].shape[1] + 7)
        assert list(demo["dones"][()]).count(1) == 1 and demo["dones"][-1] == 1
        assert demo["rewards"][-1] == float(report.episodes[0].success)
        assert [x.decode() for x in f["mask/train"][()]] == ["demo_0"] and len(f["mask/valid"][()]) == 0
    assert replay_episode(root, 0).matches


def test_cli_dataset_info_and_errors(lerobot_ds, tmp_path, capsys, monkeypatch):
    root, _ = lerobot_ds
    code, out, _ = run_main(["dataset", "info", str(root)], capsys, monkeypatch)
    assert code == 0 and "2/2 (100.0%)" in out and "observation.images.wrist" in out
    code, _, err = run_main(["run", "pick-place", "--dataset", str(root)], capsys, monkeypatch)
    assert code == 2 and "not empty" in err
    code, _, err = run_main(["run", "pick-place", "--dataset", str(tmp_path / "x"), "--dataset-fps", "7"], capsys, monkeypatch)
    assert code == 2 and "does not divide" in err
    code, _, err = run_main(["dataset", "replay", str(root), "--episode", "5"], capsys, monkeypatch)
    assert code == 2 and "has 2 episode(s)" in err


def test_keep_success_drops_failures_and_keep_all_labels_them(tmp_path, capsys, monkeypatch):
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    doc.pop("cameras")
    doc["pick_place"]["timeouts"] = {"lift": 0.1}  # the lift move needs longer: the episode fails there
    task = tmp_path / "failing_lift.yaml"
    task.write_text(yaml.safe_dump(doc))
    code, _, _ = run_main(["run", "pick-place", str(task), "--dataset", str(tmp_path / "ok_only"), "-q"], capsys, monkeypatch)
    assert code == 1
    info = json.loads((tmp_path / "ok_only/meta/info.json").read_text())
    assert info["total_episodes"] == 0 and info["total_frames"] == 0
    code, _, _ = run_main(["run", "pick-place", str(task), "--dataset", str(tmp_path / "all"), "--keep", "all",
                           "--dataset-format", "hdf5", "-q"], capsys, monkeypatch)
    assert code == 1
    with h5py.File(tmp_path / "all/data.hdf5", "r") as f:
        a = f["data/demo_0"].attrs
        assert not a["success"] and a["failed_phase"] == "lift" and "timeout" in a["reason"]
        assert f["data/demo_0/rewards"][-1] == 0.0
    code, out, _ = run_main(["dataset", "replay", str(tmp_path / "all"), "--episode", "0"], capsys, monkeypatch)
    assert code == 0 and "False / False" in out and "matches" in out


def test_grasp_and_trajectory_record_through_the_engine_and_replay(tmp_path, capsys, monkeypatch):
    """--dataset on the other episode kinds: the same sink, driven by the engine; replay matches,
    and tampered trajectory actions do not (the TCP, there being no object, ends elsewhere)."""
    code, _, _ = run_main(["run", "grasp", "-n", "1", "--dataset", str(tmp_path / "grasp"), "--keep", "all",
                             "--dataset-fps", "10", "-q"], capsys, monkeypatch)
    assert code in (0, 1)
    info = json.loads((tmp_path / "grasp/meta/info.json").read_text())
    assert info["total_episodes"] == 1 and info["robocfg"]["phases"][:2] == ["settle", "pre_grasp"]
    data = pq.read_table(tmp_path / "grasp/data/chunk-000/file-000.parquet")
    assert data.num_rows == info["total_frames"] > 10
    phases = {info["robocfg"]["phases"][i] for i in np.unique(data["phase_index"].to_numpy())}
    assert {"settle", "approach", "grasp", "lift"} <= phases
    tasks = pq.read_table(tmp_path / "grasp/meta/tasks.parquet").to_pydict()["__index_level_0__"]
    assert len(tasks) == 1 and tasks[0].startswith("grasp the ") and tasks[0].endswith(" and lift it")
    r = replay_episode(tmp_path / "grasp", 0)
    assert r.matches and r.distance < 1e-3

    traj = tmp_path / "traj"
    code, _, _ = run_main(["run", "trajectory", "--dataset", str(traj), "--dataset-format", "hdf5", "-q",
                           "--json", str(tmp_path / "traj.json")], capsys, monkeypatch)
    assert code == 0
    # the plan goes out one frame ahead of the gate's lag: the arm follows it on time (4.5e-2 rad RMS without)
    assert json.loads((tmp_path / "traj.json").read_text())["tracking"]["rms"] < 5e-3
    with h5py.File(traj / "data.hdf5", "r") as f:
        demo = f["data/demo_0"]
        assert demo["obs/object_state"].shape == (demo.attrs["num_samples"], 0)  # no object
        assert demo.attrs["language"].startswith("move the arm through")
    r = replay_episode(traj, 0)
    assert r.matches and r.replayed_success
    with h5py.File(traj / "data.hdf5", "r+") as f:
        f["data/demo_0/actions"][-5:, 0] += 0.1  # the first joint's last targets moved by 0.1 rad
    r = replay_episode(traj, 0)
    assert not r.matches and r.distance > 0.01
    code, _, err = run_main(["run", "trajectory", "--no-sim", "--dataset", str(tmp_path / "x")], capsys, monkeypatch)
    assert code == 2 and "--dataset needs the simulation" in err


def test_dataset_cameras_through_the_render_mirror_look_like_the_exact_render(tmp_path):
    """The default dataset renderer (low-poly mirror, static bodies baked) draws what TinyRenderer
    draws on the full meshes: same colours almost everywhere, depth within a few mm; the baked
    background of the fixed camera survives the wrist camera's every-frame view."""
    from robocfg.sim.camera_rig import CameraRig
    from robocfg.sim.world import World

    task = load_task(_task_file(tmp_path, depth=True))
    with World(task) as world:
        world.add_body(task.config.pick_place.object)
        arm = world.robot.arm()
        exact = CameraRig(world, arm, task.config.cameras, "exact").render_all()
        rig = CameraRig(world, arm, task.config.cameras, "tiny")
        try:
            for _ in range(2):
                fast = rig.render_all()
            assert rig._mirror is not None and len(rig._mirror._background) == 2  # one per camera view
        finally:
            rig.close()
    for name in exact:
        a, b = exact[name].rgb.astype(int), fast[name].rgb.astype(int)
        assert a.shape == b.shape == (32, 32, 3)
        assert np.mean(np.abs(a - b).max(axis=-1) > 40) < 0.1, name
    d_exact, d_fast = exact["wrist"].depth, fast["wrist"].depth
    assert d_exact is not None and d_fast is not None
    assert np.median(np.abs(d_exact - d_fast)) < 0.005


def test_an_episode_that_raises_leaves_no_recorder_hooked(tmp_path):
    """The engine stops the episode's recorder whatever ends the episode: after an exception the
    world has no step hook left and the arm's commands reach the drives again."""
    from robocfg.engine import RunOptions, open_session

    task = load_task(ROOT / "robocfg/data/tasks/pick_place.yaml")
    sink = DatasetSink(tmp_path / "ds", "lerobot", task, renderer="exact", extra_info={"task_path": str(task.path)})
    with open_session(task, RunOptions(seed=0, sink=sink)) as session:
        arm = session.world.robot.arm()

        def failing(k, recorder):
            session.record_from(arm, None, lambda: "setup")
            assert session.world.step_hooks and "command" in arm.__dict__  # recording: the gate has the arm
            session.world.step(3)
            raise RuntimeError("boom")

        session.episode = failing
        with pytest.raises(RuntimeError, match="boom"):
            session.run(0)
        assert session.world.step_hooks == [] and "command" not in arm.__dict__
        assert session.world.play_through is None
    assert sink.close().episodes_run == 0  # an episode that raised is not written


@pytest.mark.parametrize("fmt", ["lerobot", "hdf5"])
def test_recorded_moves_play_through_the_gate_bit_for_bit(tmp_path, monkeypatch, fmt):
    """A recorded episode's moves are played by the recorder (``World.play_through``: the gate's
    commands without per-step calls): the same report and the same dataset bytes as sending
    every row through ``arm.command`` and ``world.step``."""
    import dataclasses

    import robocfg.sim.playback as playback
    from robocfg.datasets.recorder import EpisodeRecorder

    task = load_task(ROOT / "robocfg/data/tasks/pick_place.yaml")
    task = dataclasses.replace(task, config=task.config.model_copy(update={"cameras": []}))

    def record(root: Path):
        sink = DatasetSink(root, fmt, task, keep="all", extra_info={"task_path": "pick_place.yaml", "seed": 1})
        report, _ = run_pick_place(task, 2, seed=1, sink=sink)
        sink.close()
        return report, {f.relative_to(root): f.read_bytes() for f in sorted(root.rglob("*")) if f.is_file()}

    played: list[int] = []
    real = playback.play_latched
    monkeypatch.setattr(playback, "play_latched", lambda *a: played.append(len(a[2])) or real(*a))
    fast = record(tmp_path / "fast")
    assert sum(played) > 1000  # most of the episodes' steps were played through the gate
    monkeypatch.setattr(EpisodeRecorder, "play", lambda self, *a: False)
    played.clear()
    slow = record(tmp_path / "slow")
    assert not played
    assert fast[0] == slow[0] and all(e.success for e in fast[0].episodes)
    assert fast[1].keys() == slow[1].keys() and fast[1] == slow[1]
