"""LeRobot v3.0 conformance of a dataset directory, checked with pyarrow and PyAV alone (no lerobot,
no torch): what ``LeRobotDataset`` relies on when it loads a dataset of one or many files.

* ``meta/info.json``: codebase v3.0, the path templates, the file limits (``chunks_size``,
  ``data_files_size_in_mb``, ``video_files_size_in_mb``), totals that match the files;
* every series (``meta/episodes``, ``data``, ``videos/<key>``) is ``chunk-CCC/file-FFF`` files
  numbered as lerobot numbers them (file 0 of chunk 0, then the next file, a new chunk after
  ``chunks_size`` files), none empty;
* ``meta/episodes``: episodes 0..N-1 in order, each row naming its own metadata file, contiguous
  ``dataset_from_index`` / ``dataset_to_index``;
* ``data``: the dtypes and shapes ``info.json`` declares; ``index`` 0..frames-1 over the files in
  order; every episode's rows lie, whole and in frame order, in the file its metadata names, at
  its index range; ``timestamp = frame_index / fps``;
* ``videos/<key>``: each file's decoded frame count = the frames of the episodes naming it, frame i
  of a file at i / fps, each episode's ``from_timestamp`` = the frames before it in its file / fps
  and ``to_timestamp`` = from + length / fps, frames of the declared size;
* ``meta/stats.json`` has every feature.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import av
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

_NAME = re.compile(r"chunk-(\d{3})/file-(\d{3})\.(parquet|mp4)$")


@dataclass
class Conformance:
    """What the check saw: episodes' metadata rows, the files of each series (relative paths, in
    order) and the decoded frame count of each video file."""

    episodes: list[dict]
    files: dict[str, list[str]] = field(default_factory=dict)
    video_frames: dict[str, int] = field(default_factory=dict)


def _series(root: Path, folder: str, suffix: str, chunks_size: int) -> list[Path]:
    """The files of one series in order, checking lerobot's numbering."""
    paths = sorted((root / folder).glob(f"chunk-*/file-*.{suffix}"))
    assert paths, f"{folder}: no file"
    expected = (0, 0)
    for p in paths:
        m = _NAME.search(p.relative_to(root).as_posix())
        assert m, f"{p}: not chunk-CCC/file-FFF"
        assert (int(m.group(1)), int(m.group(2))) == expected, f"{p}: expected chunk/file {expected}"
        expected = (expected[0] + 1, 0) if expected[1] == chunks_size - 1 else (expected[0], expected[1] + 1)
    return paths


def _chunk_file(root: Path, path: Path) -> tuple[int, int]:
    m = _NAME.search(path.relative_to(root).as_posix())
    assert m
    return int(m.group(1)), int(m.group(2))


def check_lerobot(root: Path) -> Conformance:
    """Check the dataset at ``root``; returns what it saw (asserts on any departure)."""
    root = Path(root)
    info = json.loads((root / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0"
    assert info["data_path"] == "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
    for key in ("chunks_size", "data_files_size_in_mb", "video_files_size_in_mb"):
        assert isinstance(info[key], int | float) and info[key] > 0, key
    fps, chunks = info["fps"], info["chunks_size"]
    feats = info["features"]
    video_keys = [k for k, v in feats.items() if v["dtype"] == "video"]
    if video_keys:
        assert info["video_path"] == "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
    seen = Conformance(episodes=[])

    meta_files = _series(root, "meta/episodes", "parquet", chunks)
    seen.files["meta/episodes"] = [str(p.relative_to(root)) for p in meta_files]
    tables = [pq.read_table(p) for p in meta_files]
    assert all(t.schema == tables[0].schema for t in tables), "meta/episodes files differ in schema"
    for p, t in zip(meta_files, tables, strict=True):
        chunk, file = _chunk_file(root, p)
        rows = t.to_pylist()
        assert rows, f"{p}: empty"
        for r in rows:
            assert (r["meta/episodes/chunk_index"], r["meta/episodes/file_index"]) == (chunk, file), p
        seen.episodes += rows
    eps = seen.episodes
    assert [e["episode_index"] for e in eps] == list(range(len(eps))) and len(eps) == info["total_episodes"]
    start = 0
    for e in eps:
        assert e["dataset_from_index"] == start and e["dataset_to_index"] == start + e["length"] > start
        start = e["dataset_to_index"]
    assert start == info["total_frames"]

    data_files = _series(root, "data", "parquet", chunks)
    seen.files["data"] = [str(p.relative_to(root)) for p in data_files]
    first = 0
    for p in data_files:
        t = pq.read_table(p)
        assert t.num_rows, f"{p}: empty"
        _check_dtypes(t, feats, p)
        index = t["index"].to_numpy()
        assert np.array_equal(index, np.arange(first, first + t.num_rows)), f"{p}: index not consecutive"
        frame = t["frame_index"].to_numpy()
        np.testing.assert_allclose(t["timestamp"].to_numpy(), frame / fps, atol=1e-6, err_msg=str(p))
        where = _chunk_file(root, p)
        mine = [e for e in eps if (e["data/chunk_index"], e["data/file_index"]) == where]
        assert mine and mine[0]["dataset_from_index"] == first and mine[-1]["dataset_to_index"] == first + t.num_rows, \
            f"{p}: holds other rows than the episodes naming it"
        ep_col = t["episode_index"].to_numpy()
        for e in mine:
            a, b = e["dataset_from_index"] - first, e["dataset_to_index"] - first
            assert np.all(ep_col[a:b] == e["episode_index"]), f"{p}: episode {e['episode_index']} rows"
            assert np.array_equal(frame[a:b], np.arange(e["length"])), f"{p}: episode {e['episode_index']} frames"
        first += t.num_rows
    assert first == info["total_frames"]

    for key in video_keys:
        files = _series(root, f"videos/{key}", "mp4", chunks)
        seen.files[f"videos/{key}"] = [str(p.relative_to(root)) for p in files]
        h, w = feats[key]["shape"][:2]
        named = {(e[f"videos/{key}/chunk_index"], e[f"videos/{key}/file_index"]) for e in eps}
        assert named == {_chunk_file(root, p) for p in files}, f"{key}: files and metadata disagree"
        for p in files:
            where = _chunk_file(root, p)
            mine = [e for e in eps if (e[f"videos/{key}/chunk_index"], e[f"videos/{key}/file_index"]) == where]
            with av.open(str(p)) as c:
                frames = list(c.decode(video=0))
            n = sum(e["length"] for e in mine)
            assert len(frames) == n, f"{p}: {len(frames)} frames, its episodes have {n}"
            np.testing.assert_allclose([float(f.time) for f in frames], np.arange(n) / fps, atol=1e-6, err_msg=str(p))
            assert (frames[0].height, frames[0].width) == (h, w)
            before = 0
            for e in mine:
                assert abs(e[f"videos/{key}/from_timestamp"] - before / fps) < 1e-9, f"{p}: episode {e['episode_index']}"
                assert abs(e[f"videos/{key}/to_timestamp"] - (before + e["length"]) / fps) < 1e-9
                before += e["length"]
            seen.video_frames[str(p.relative_to(root))] = len(frames)

    stats = json.loads((root / "meta/stats.json").read_text())
    if eps:
        assert set(feats) <= set(stats), f"stats.json lacks {set(feats) - set(stats)}"
    return seen


def _check_dtypes(t: pa.Table, feats: dict, path: Path) -> None:
    """The data columns are what ``info.json`` declares (video features live in the MP4 files)."""
    for key, f in feats.items():
        if f["dtype"] == "video":
            assert key not in t.column_names
            continue
        typ = t.schema.field(key).type
        if key == "timestamp":
            assert typ == pa.float32(), path
        elif f["dtype"] == "int64":
            assert typ == pa.int64(), (path, key)
        else:  # float32 vectors (fixed-size lists) and (H, W) depth (lists of lists)
            for size in f["shape"]:  # outer list first: (H, W) depth is H lists of W
                assert pa.types.is_fixed_size_list(typ) and typ.list_size == size, (path, key, typ)
                typ = typ.value_type
            assert typ == pa.float32(), (path, key)
