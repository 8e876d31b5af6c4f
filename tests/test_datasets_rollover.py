"""LeRobot v3.0 file rollover: data, episode metadata and each camera's video files start a new file
where the current one would reach its size limit, a new chunk directory every ``chunks_size``
files, as lerobot 0.4.4 does; every episode's frames are in the files its metadata names, and a
merge of (multi-file) shards is the dataset one writer writes."""

from __future__ import annotations

import json
from pathlib import Path

import av
import numpy as np
import pyarrow.parquet as pq
import pytest
from _cli import run_main
from _lerobot_conformance import check_lerobot
from _parallel import files_of, run_json, small_camera_task
from test_datasets_streaming import LAYOUT, _files
from test_datasets_streaming import _episode as _noisy_episode

from robocfg.datasets.files import MB, FileLimits, FileSeries, next_file
from robocfg.datasets.lerobot import DATA_PATH, VIDEO_PATH, LeRobotWriter
from robocfg.datasets.read import read_episode, read_info
from robocfg.datasets.shards import Shard, merge_shards
from robocfg.datasets.video import encode_episode

# The synthetic episodes are 5-7 frames of 16x16: 5 600-7 840 bytes of data rows, ~1.7-1.8 kB of
# video each. These limits put 3 episodes in a data file, 2 in a video file.
LIMITS = FileLimits(chunks_size=2, data_files_size_in_mb=0.02, video_files_size_in_mb=0.004)
KEY = "observation.images.wrist"


def _episode(k: int):
    """test_datasets_streaming's episode k with images H.264 keeps recognisable at 16x16 (a flat
    colour per frame and a ramp; noise would not survive the codec)."""
    ep = _noisy_episode(k)
    colour = np.random.default_rng([8, k]).integers(30, 226, (ep.length, 1, 1, 3))
    ramp = 2 * np.arange(16)[None, :, None, None]
    ep.images["wrist"] = np.broadcast_to(colour + ramp, (ep.length, 16, 16, 3)).astype(np.uint8)
    return ep


def _write(root: Path, episodes, limits: FileLimits = LIMITS) -> LeRobotWriter:
    w = LeRobotWriter(root, LAYOUT, {"seed": 7}, limits)
    for ep in episodes:
        w.add(ep)
    w.close()
    return w


def test_next_file_and_the_rollover_rule():
    assert next_file(0, 0, 3) == (0, 1) and next_file(0, 2, 3) == (1, 0) and next_file(4, 0, 1) == (5, 0)
    s = FileSeries(limit_mb=100 / MB, chunks_size=2)  # a 100-byte limit
    assert not s.add(150)  # larger than the limit: still the first file's, alone
    assert s.add(1) and (s.chunk, s.file) == (0, 1)
    assert not s.add(98) and s.size == 99  # 99 < 100: the same file
    assert s.rolls(1) and s.add(1) and (s.chunk, s.file) == (1, 0)  # would reach 100: next file, next chunk
    for bad in ({"chunks_size": 0}, {"chunks_size": 1001}, {"data_files_size_in_mb": 0},
                {"video_files_size_in_mb": -1.0}):
        with pytest.raises(ValueError, match="must be"):
            FileLimits(**bad)  # type: ignore[arg-type]


def test_files_roll_over_where_the_limits_say_and_hold_the_frames_written(tmp_path):
    eps = [_episode(k) for k in range(8)]
    root = tmp_path / "ds"
    _write(root, eps)
    seen = check_lerobot(root)
    assert seen.files["data"] == ["data/chunk-000/file-000.parquet", "data/chunk-000/file-001.parquet",
                                  "data/chunk-001/file-000.parquet"]
    assert seen.files[f"videos/{KEY}"] == [f"videos/{KEY}/chunk-{c:03d}/file-{f:03d}.mp4"
                                          for c, f in ((0, 0), (0, 1), (1, 0), (1, 1))]
    assert seen.files["meta/episodes"] == ["meta/episodes/chunk-000/file-000.parquet"]
    info = json.loads((root / "meta/info.json").read_text())
    assert (info["chunks_size"], info["data_files_size_in_mb"], info["video_files_size_in_mb"]) == (2, 0.02, 0.004)
    rows = seen.episodes
    # the rule, episode by episode: a new file exactly where the current one would reach the limit
    data_bytes = [_rows_nbytes(root, r) for r in rows]
    video_bytes = [len(encode_episode(ep.images["wrist"], LAYOUT.fps).data) for ep in eps]
    for col, sizes, limit in (("data", data_bytes, LIMITS.data_files_size_in_mb),
                              (f"videos/{KEY}", video_bytes, LIMITS.video_files_size_in_mb)):
        in_file = 0
        for i, r in enumerate(rows):
            new = i > 0 and (r[f"{col}/chunk_index"], r[f"{col}/file_index"]) != (
                rows[i - 1][f"{col}/chunk_index"], rows[i - 1][f"{col}/file_index"])
            assert new == (i > 0 and in_file + sizes[i] >= limit * MB), (col, i)
            in_file = sizes[i] if new else in_file + sizes[i]
    # what was written is in the file the metadata names: exact rows, decoded video near the images
    for r, ep in zip(rows, eps, strict=True):
        t = pq.read_table(root / DATA_PATH.format(chunk_index=r["data/chunk_index"], file_index=r["data/file_index"]))
        mine = t.filter(np.asarray(t["episode_index"].to_numpy() == r["episode_index"]))
        assert np.array_equal(np.asarray(mine["observation.state"].to_pylist(), np.float32), ep.state)
        depth = mine["observation.depth.wrist"].combine_chunks().flatten().flatten().to_numpy().reshape(ep.length, 16, 16)
        assert np.array_equal(depth, ep.depth["wrist"])
        frames = _decode(root / VIDEO_PATH.format(video_key=KEY, chunk_index=r[f"videos/{KEY}/chunk_index"],
                                                  file_index=r[f"videos/{KEY}/file_index"]),
                         r[f"videos/{KEY}/from_timestamp"], ep.length, LAYOUT.fps)
        err = np.abs(frames.astype(float) - ep.images["wrist"]).mean()
        other = np.abs(frames.astype(float) - np.roll(ep.images["wrist"], 1, axis=0)).mean()
        assert err < 0.5 * other, (r["episode_index"], err, other)  # these frames, not their neighbours


def _rows_nbytes(root: Path, r: dict) -> int:
    """The Arrow size of an episode's data rows as the writer counts them (no validity bitmaps):
    4 bytes a float32 value, 8 an int64, per frame (parquet's reader adds bitmaps on read-back)."""
    feats = json.loads((root / "meta/info.json").read_text())["features"]
    per_frame = sum(8 if f["dtype"] == "int64" else 4 * int(np.prod(f["shape"]))
                    for f in feats.values() if f["dtype"] != "video")
    return per_frame * r["length"]


def _decode(path: Path, t0: float, n: int, fps: int) -> np.ndarray:
    """``n`` RGB frames of ``path`` from ``t0`` s on."""
    with av.open(str(path)) as c:
        frames = [f.to_ndarray(format="rgb24") for f in c.decode(video=0) if round(float(f.time) * fps) >= round(t0 * fps)]
    return np.stack(frames[:n])


def test_episode_metadata_rolls_over_too_and_readers_follow_every_file(tmp_path):
    """A limit below one episode: every episode its own data, metadata and video file (and a new
    chunk every 2); ``dataset info`` counts them, ``read_episode`` finds each one's actions."""
    eps = [_episode(k) for k in range(5)]
    root = tmp_path / "ds"
    _write(root, eps, FileLimits(chunks_size=2, data_files_size_in_mb=1e-6, video_files_size_in_mb=1e-6))
    seen = check_lerobot(root)
    assert len(seen.files["meta/episodes"]) == len(seen.files["data"]) == len(seen.files[f"videos/{KEY}"]) == 5
    assert seen.files["meta/episodes"][-1] == "meta/episodes/chunk-002/file-000.parquet"
    info = read_info(root)
    assert info.episodes == 5 and info.frames == sum(e.length for e in eps) and info.successes == 5
    assert info.files == {"data": 5, "meta/episodes": 5, f"videos/{KEY}": 5}
    for k in (0, 3, 4):
        assert np.array_equal(read_episode(root, k).actions, eps[k].action.astype(np.float64))


@pytest.mark.parametrize("limits", [LIMITS, FileLimits(chunks_size=1, data_files_size_in_mb=0.012,
                                                        video_files_size_in_mb=0.003)])
def test_a_merge_of_multi_file_shards_is_the_dataset_one_writer_writes(tmp_path, limits):
    """Shards rolled over at the same limits (so read back file by file), merged in any order:
    byte for byte what one writer writes, however the episodes fell into shards."""
    eps = [_episode(k) for k in range(8)]
    one = tmp_path / "one"
    _write(one, eps, limits)
    assert len(list((one / "data").rglob("*.parquet"))) > 1
    shards = []
    for i, part in enumerate((eps[:4], eps[4:5], eps[5:])):
        root = tmp_path / f"shard{i}"
        w = _write(root, part, limits)
        st = w.image_stats["wrist"]
        shards.append(Shard(str(root), "lerobot", LAYOUT, len(part), len(part), sum(e.length for e in part),
                            {"wrist": st.hist.copy()}, {"wrist": st.frames}, tuple(e.index for e in part)))
    merged = tmp_path / "merged"
    merge_shards(shards[::-1], merged, "lerobot", {"seed": 7}, remove=False, limits=limits)
    a, b = _files(one), _files(merged)
    assert list(a) == list(b)
    for name in a:
        assert a[name] == b[name], f"{name} differs"


def test_a_recorded_multi_file_run_conforms_is_the_same_on_two_workers_and_replays(tmp_path, capsys, monkeypatch):
    """A real pick-place run (scene camera, wrist camera with depth) recorded with small limits:
    several data and video files, the same files on 1 and 2 workers (shards rolled over, then
    merged), ``dataset info`` counts the files and an episode of the second data file replays."""
    task = str(small_camera_task(tmp_path))
    common = ["run", "pick-place", task, "-n", "3", "--seed", "5", "--dataset-fps", "10", "--keep", "all",
              "--dataset-data-mb", "0.6", "--dataset-video-mb", "0.025", "--dataset-chunk-files", "2"]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    two = run_json([*common, "--workers", "2", "--dataset", str(tmp_path / "two")], tmp_path, "two", capsys, monkeypatch)
    assert one == two
    a, b = files_of(tmp_path / "one"), files_of(tmp_path / "two")
    assert list(a) == list(b)
    for name in a:
        assert a[name] == b[name], f"{name} differs"
    seen = check_lerobot(tmp_path / "one")
    assert len(seen.files["data"]) == 2 and seen.files["data"][1] == "data/chunk-000/file-001.parquet"
    for cam in ("scene", "wrist"):
        assert len(seen.files[f"videos/observation.images.{cam}"]) >= 2
    last = seen.episodes[-1]
    assert (last["data/chunk_index"], last["data/file_index"]) == (0, 1)
    code, _, _ = run_main(["dataset", "info", str(tmp_path / "one"), "--json", str(tmp_path / "info.json")],
                          capsys, monkeypatch)
    assert code == 0
    files = json.loads((tmp_path / "info.json").read_text())["files"]
    assert files == {"data": 2, "meta/episodes": 1, **{k: len(v) for k, v in seen.files.items() if k.startswith("videos/")}}
    code, out, _ = run_main(["dataset", "replay", str(tmp_path / "one"), "--episode", "2"], capsys, monkeypatch)
    assert code == 0 and "matches" in out


@pytest.mark.parametrize(("flag", "value"), [("--dataset-data-mb", "0"), ("--dataset-video-mb", "-1"),
                                             ("--dataset-chunk-files", "1001")])
def test_bad_file_limits_are_user_errors(flag, value, tmp_path, capsys, monkeypatch):
    code, _, err = run_main(["run", "pick-place", "--dataset", str(tmp_path / "x"), flag, value], capsys, monkeypatch)
    assert code == 2 and flag in err and "must be" in err and not (tmp_path / "x").exists()
