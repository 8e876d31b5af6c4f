"""The LeRobot writer streams its data rows (depth included) to the parquet file as episodes come,
in row groups cut where the buffered rows reach ``ROW_GROUP_BYTES``; a merge of shards reads one
shard at a time and gives the bytes one writer gives, however the rows were cut."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from robocfg.datasets import lerobot
from robocfg.datasets.episode import CameraLayout, DatasetLayout, EpisodeRecord
from robocfg.datasets.lerobot import DATA_PATH, LeRobotWriter
from robocfg.datasets.shards import Shard, merge_shards

H = W = 16
LAYOUT = DatasetLayout(fps=10, robot="bot", task_name="t", state_names=("j1", "j2", "g"),
                       env_state_names=("x", "y", "z", "qx", "qy", "qz", "qw"), action_names=("j1", "j2", "g"),
                       phases=("run",), cameras=(CameraLayout("wrist", H, W, True),))


def _episode(k: int) -> EpisodeRecord:
    rng = np.random.default_rng([7, k])
    n = 5 + k % 3
    return EpisodeRecord(index=k, seed=7, language="pick it", success=True, failed_phase=None, reason="",
                         physics_steps=10 * n, object_final=[0.0] * 7,
                         state=rng.normal(size=(n, 3)).astype(np.float32),
                         env_state=rng.normal(size=(n, 7)).astype(np.float32),
                         action=rng.normal(size=(n, 3)).astype(np.float32), phase=np.zeros(n, np.int64),
                         images={"wrist": rng.integers(0, 256, (n, H, W, 3), dtype=np.uint8)},
                         depth={"wrist": rng.uniform(0.05, 2.0, (n, H, W)).astype(np.float32)})


def _write(root: Path, episodes: list[EpisodeRecord]) -> LeRobotWriter:
    w = LeRobotWriter(root, LAYOUT, {"seed": 7})
    for ep in episodes:
        w.add(ep)
    w.close()
    return w


def _files(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_rows_reach_the_file_as_episodes_come_and_read_back_the_same(tmp_path, monkeypatch):
    eps = [_episode(k) for k in range(4)]
    whole = tmp_path / "whole"
    _write(whole, eps)  # under ROW_GROUP_BYTES: one row group, as pyarrow's write_table writes it
    assert pq.ParquetFile(whole / DATA_PATH.format(chunk_index=0, file_index=0)).num_row_groups == 1

    monkeypatch.setattr(lerobot, "ROW_GROUP_BYTES", 1)  # every episode is its own row group
    streamed = tmp_path / "streamed"
    w = LeRobotWriter(streamed, LAYOUT, {"seed": 7})
    data = streamed / DATA_PATH.format(chunk_index=0, file_index=0)
    sizes = []
    for ep in eps:
        w.add(ep)
        assert w._pending == []  # nothing of the episode is left buffered in the writer
        sizes.append(data.stat().st_size)
    depth_bytes = [4 * H * W * ep.length for ep in eps]
    assert all(b - a >= 0.9 * d for a, b, d in zip(sizes, sizes[1:], depth_bytes[1:], strict=False))  # on disk
    w.close()
    assert pq.ParquetFile(data).num_row_groups == 4
    a, b = pq.read_table(whole / DATA_PATH.format(chunk_index=0, file_index=0)), pq.read_table(data)
    assert a.equals(b)
    for name in ("meta/stats.json", "meta/info.json", "meta/episodes/chunk-000/file-000.parquet",
                 "meta/tasks.parquet", "videos/observation.images.wrist/chunk-000/file-000.mp4"):
        assert (whole / name).read_bytes() == (streamed / name).read_bytes(), name
    stats = json.loads((streamed / "meta/stats.json").read_text())["observation.depth.wrist"]
    depth = np.concatenate([ep.depth["wrist"] for ep in eps]).astype(np.float64)
    assert stats["mean"][0][0] == pytest.approx(depth.mean(), rel=1e-12)
    assert stats["count"] == [sum(ep.length for ep in eps)]


@pytest.mark.parametrize("row_group_bytes", [1, 12_000, lerobot.ROW_GROUP_BYTES])
def test_a_merge_of_shards_is_the_dataset_one_writer_writes(tmp_path, monkeypatch, row_group_bytes):
    """Shards merged one at a time (given in any order) give, byte for byte, what one writer gives,
    with the row groups cut after every episode, every few episodes, or never."""
    monkeypatch.setattr(lerobot, "ROW_GROUP_BYTES", row_group_bytes)
    eps = [_episode(k) for k in range(5)]
    one = tmp_path / "one"
    _write(one, eps)
    groups = pq.ParquetFile(one / DATA_PATH.format(chunk_index=0, file_index=0)).num_row_groups
    assert groups == {1: 5, 12_000: 3}.get(row_group_bytes, 1)
    shards = []
    for i, part in enumerate((eps[:2], eps[2:3], eps[3:])):
        root = tmp_path / f"shard{i}"
        w = _write(root, part)
        st = w.image_stats["wrist"]
        shards.append(Shard(str(root), "lerobot", LAYOUT, len(part), len(part), sum(e.length for e in part),
                            {"wrist": st.hist.copy()}, {"wrist": st.frames}, tuple(e.index for e in part)))
    merged = tmp_path / "merged"
    summary = merge_shards(shards[::-1], merged, "lerobot", {"seed": 7}, remove=False)
    assert summary.episodes_kept == 5 and summary.frames == sum(e.length for e in eps)
    a, b = _files(one), _files(merged)
    assert list(a) == list(b)
    for name in a:
        assert a[name] == b[name], f"{name} differs"
