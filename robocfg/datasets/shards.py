"""Dataset shards: what one worker of a parallel run writes, and their merge into one dataset.

A shard is an ordinary dataset (LeRobot v3.0 directory or robomimic HDF5 file) holding the kept
episodes of one batch of a run, written by the same writer as a single-process run. The merge
reads every shard back and hands the episodes, ordered by their episode index in the run, to a
fresh writer: data rows, episode metadata and task indices are renumbered, statistics are
recomputed over all frames (image statistics summed from the shards' exact colour histograms),
and LeRobot videos are joined by copying each episode's packets. The merged dataset is therefore
the same, file for file, as the one a single process writes for the same task and seed, however
the episodes were spread over workers.
"""

from __future__ import annotations

import itertools
import shutil
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.datasets.episode import DatasetLayout, EpisodeRecord
from robocfg.datasets.files import FileLimits
from robocfg.datasets.sink import DatasetSink, DatasetSummary, Format, make_writer
from robocfg.datasets.stats import ImageStats


@dataclass(frozen=True)
class Shard:
    """One closed shard: where it is, its format, the layout of its episodes (None when no episode
    was run into it), episodes run and kept, frames, its cameras' colour histograms (camera →
    (3, 256) counts, with the number of frames they cover) and the run's indices of the episodes
    it holds, in order."""

    path: str
    fmt: Format
    layout: DatasetLayout | None
    episodes_run: int
    episodes_kept: int
    frames: int
    image_hist: dict[str, np.ndarray] = field(default_factory=dict)
    image_frames: dict[str, int] = field(default_factory=dict)
    indices: tuple[int, ...] = ()


def close_shard(sink: DatasetSink) -> Shard:
    """Close ``sink`` (a sink writing into a shard folder) and describe what it holds."""
    sink.close()
    hist: dict[str, np.ndarray] = {}
    frames: dict[str, int] = {}
    stats = getattr(sink.writer, "image_stats", None) or {}
    for name, s in stats.items():
        hist[name], frames[name] = s.hist.copy(), s.frames
    return Shard(str(sink.root), sink.fmt, sink.layout, sink.run, sink.kept, sink.frames, hist, frames,
                 tuple(sink.kept_indices))


def merge_shards(shards: list[Shard], out: Path, fmt: Format, extra_info: dict,
                 remove: bool = True, limits: FileLimits | None = None) -> DatasetSummary:
    """Write the episodes of ``shards`` into the dataset ``out`` ordered by their episode index
    in the run (a LeRobot dataset's files rolled over at ``limits``, as one writer does);
    ``remove`` deletes the shard folders afterwards."""
    out = Path(out)
    layouts = [s.layout for s in shards if s.layout is not None]
    run = sum(s.episodes_run for s in shards)
    if not layouts:  # no episode ran (every worker lost): an empty dataset is still no dataset
        return DatasetSummary(str(out), fmt, 0, run, 0)
    layout = layouts[0]
    writer = make_writer(fmt, out, layout, extra_info, limits)
    frames = kept = 0
    for ep, videos in _in_order([s for s in shards if s.episodes_kept], layout):
        if fmt == "lerobot":
            writer.add_encoded(ep, videos)
        else:
            writer.add(ep)
        frames += ep.length
        kept += 1
    if fmt == "lerobot":
        writer.add_image_histograms(_summed_histograms(shards))
    writer.close()
    if remove:
        for s in shards:
            shutil.rmtree(s.path, ignore_errors=True)
    return DatasetSummary(str(out), fmt, kept, run, frames)


def _in_order(shards: list[Shard], layout: DatasetLayout) -> Iterator[tuple[EpisodeRecord, dict]]:
    """Every episode of ``shards`` ordered by its index in the run. Shards whose index ranges do
    not interleave (a run's batches are consecutive ranges) are read one at a time, so the merge
    holds one shard's frames at most; otherwise all are read, then sorted."""
    def read(s: Shard) -> list[tuple[EpisodeRecord, dict]]:
        return _read_lerobot(s, layout) if s.fmt == "lerobot" else _read_hdf5(s, layout)

    ordered = sorted(shards, key=lambda s: s.indices[0] if s.indices else -1)
    apart = all(s.indices and list(s.indices) == sorted(s.indices) for s in ordered) and all(
        a.indices[-1] < b.indices[0] for a, b in itertools.pairwise(ordered))
    if not apart:
        yield from sorted((e for s in shards for e in read(s)), key=lambda e: e[0].index)
        return
    for s in ordered:
        yield from read(s)


def _summed_histograms(shards: list[Shard]) -> dict[str, ImageStats]:
    total: dict[str, ImageStats] = {}
    for s in shards:
        for name, hist in s.image_hist.items():
            st = total.setdefault(name, ImageStats())
            st.hist += hist
            st.frames += s.image_frames[name]
    return total


def _read_lerobot(shard: Shard, layout: DatasetLayout) -> list[tuple[EpisodeRecord, dict]]:
    from robocfg.datasets.lerobot import (
        ACTION,
        ACTION_EE,
        ACTION_JOINT,
        ENV,
        STATE,
        VIDEO_PATH,
        depth_key,
        image_key,
        vector_dims,
    )
    from robocfg.datasets.lerobot_meta import read_data, read_episodes
    from robocfg.datasets.video import split_segments

    root = Path(shard.path)
    rows = read_episodes(root).to_pylist()
    data = read_data(root)  # every data file of the shard, in order
    dims = vector_dims(layout)
    cols = {k: np.asarray(data[k].combine_chunks().flatten().to_numpy(zero_copy_only=False)) for k in dims}
    vec = {k: cols[k].astype(np.float32).reshape(-1, d) for k, d in dims.items()}
    if ENV not in vec:  # no object: zero-width environment state
        vec[ENV] = np.zeros((data.num_rows, 0), np.float32)
    phase = data["phase_index"].to_numpy().astype(np.int64)
    depth = {c.name: np.asarray(data[depth_key(c.name)].combine_chunks().flatten().flatten().to_numpy(), np.float32)
             .reshape(-1, c.height, c.width) for c in layout.cameras if c.depth}
    segments: dict[str, list] = {}
    for c in layout.cameras:  # each video file's episodes, in order, back as standalone segments
        key = image_key(c.name)
        segments[c.name] = []
        for (chunk, file), group in itertools.groupby(rows, key=lambda r: (r[f"videos/{key}/chunk_index"],
                                                                           r[f"videos/{key}/file_index"])):
            path = root / VIDEO_PATH.format(video_key=key, chunk_index=chunk, file_index=file)
            segments[c.name] += split_segments(path, layout.fps, [r["length"] for r in group])
    out = []
    for i, r in enumerate(rows):
        a, b = r["dataset_from_index"], r["dataset_to_index"]
        joint, ee = (ACTION_JOINT, ACTION) if layout.actions == "ee_delta" else (ACTION, ACTION_EE)
        ep = EpisodeRecord(index=r["run_episode"], seed=r["seed"], language=r["tasks"][0], success=r["success"],
                           failed_phase=r["failed_phase"], reason=r["reason"], physics_steps=r["physics_steps"],
                           object_final=list(r["object_final"]), state=vec[STATE][a:b], env_state=vec[ENV][a:b],
                           action=vec[joint][a:b], phase=phase[a:b], depth={k: d[a:b] for k, d in depth.items()},
                           ee_delta=vec[ee][a:b] if layout.ee_delta else None)
        out.append((ep, {name: segs[i] for name, segs in segments.items()}))
    return out


def _read_hdf5(shard: Shard, layout: DatasetLayout) -> list[tuple[EpisodeRecord, dict]]:
    import h5py

    from robocfg.datasets.hdf5 import FILE_NAME

    out: list[tuple[EpisodeRecord, dict]] = []
    with h5py.File(Path(shard.path) / FILE_NAME, "r") as f:
        for name in sorted(f["data"].keys(), key=lambda n: int(n.split("_")[1])):
            g = f["data"][name]
            a = g.attrs
            obs = g["obs"]
            mode = layout.actions
            joint = g["actions_joint" if mode == "ee_delta" else "actions"][()]
            ee = g["actions" if mode == "ee_delta" else "actions_ee_delta"][()] if layout.ee_delta else None
            ep = EpisodeRecord(
                index=int(a["run_episode"]), seed=int(a["seed"]), language=str(a["language"]),
                success=bool(a["success"]), failed_phase=str(a["failed_phase"]) or None, reason=str(a["reason"]),
                physics_steps=int(a["physics_steps"]), object_final=[float(v) for v in a["object_final"]],
                state=obs["robot_state"][()], env_state=obs["object_state"][()], action=joint, ee_delta=ee,
                phase=g["phase"][()],
                images={c.name: obs[f"{c.name}_image"][()] for c in layout.cameras},
                depth={c.name: obs[f"{c.name}_depth"][()] for c in layout.cameras if c.depth})
            out.append((ep, {}))
    return out


class MergedShards:
    """The dataset sink of a distributed run's driver: the workers recorded into ``shards``;
    ``close()`` merges them into ``root`` (and removes ``root/.shards``), like a single-process
    sink's ``close()`` writes its dataset (with its file ``limits``)."""

    def __init__(self, shards: list[Shard], root: Path, fmt: Format, extra_info: dict,
                 limits: FileLimits | None = None):
        self.shards, self.root, self.fmt, self.extra_info = shards, Path(root), fmt, extra_info
        self.limits = limits

    def close(self) -> DatasetSummary:
        summary = merge_shards(self.shards, self.root, self.fmt, self.extra_info, limits=self.limits)
        shutil.rmtree(self.root / ".shards", ignore_errors=True)
        return summary
