"""A LeRobot v3.0 dataset writer with pyarrow and PyAV only (no torch, no lerobot).

Layout (``C`` chunk, ``F`` file: files roll over at lerobot's size limits, :mod:`robocfg.datasets.files`)::

    meta/info.json                      codebase_version "v3.0", fps, features, totals, paths, file size limits
    meta/stats.json                     per-feature min/max/mean/std/count/q01..q99
    meta/tasks.parquet                  task string (pandas index) -> task_index
    meta/episodes/chunk-C/file-F.parquet   one row per episode: length, index ranges, the data file
                                        and each camera's video file holding it with its time range
                                        there, tasks, and robocfg's outcome columns
    data/chunk-C/file-F.parquet         one row per frame, whole episodes per file
    videos/<key>/chunk-C/file-F.mp4     the frames of one camera, episodes back to back

A new data file starts when the current one would reach ``data_files_size_in_mb`` with the next
episode, a new video file (per camera) at ``video_files_size_in_mb``, a new chunk directory every
``chunks_size`` files (:class:`~robocfg.datasets.files.FileLimits`: lerobot 0.4.4's 100 MB, 200 MB
and 1000 by default; measured on the default pick-place at 20 Hz: state only, 100 MB of data rows
every ≈ 520 000 frames, ≈ 4 400 episodes; a 128x128 depth camera, every ≈ 1 600 frames, ≈ 13
episodes; a 128x128 camera's video, 200 MB every ≈ 2 000-2 800 episodes; docs/benchmarks.md).

Depth (a camera with ``depth: true``) is a float32 feature ``observation.depth.<camera>`` of shape
(H, W) in the data parquet, metres along the optical axis, stored exactly (a fixed-size list of
fixed-size lists: what ``LeRobotDataset`` loads as a ``datasets.Array2D``); its statistics are one
(1, 1) figure each over every pixel (:class:`~robocfg.datasets.stats.DepthStats`, running sums and a
1 mm histogram, so no frame is kept for them).

The data parquet is streamed: each episode's rows are buffered and written as a row group once
the buffer holds ``ROW_GROUP_BYTES`` (and when the file ends), so a writer holds at most that much
of the frames' data, whatever the number of episodes (depth is 64 KiB a frame at 128×128). Where
to cut depends only on the episodes in order, so a merged dataset cuts where a single process
does. A data file under ``ROW_GROUP_BYTES`` (state only: tens of thousands of frames) is one row
group, as ``pyarrow.parquet.write_table`` writes it. The vector features (state, actions: ≈ 150
bytes a frame) are also kept until ``close()``, for their exact quantiles in ``stats.json``.

Timestamps are ``frame_index / fps``; an episode's video frames start at its
``videos/<key>/from_timestamp`` in the file its ``videos/<key>/chunk_index`` and ``file_index``
name (frames before it in that file / fps; 0 for a file's first episode). Videos: H.264
(libx264), yuv420p, a keyframe every 2 frames (LeRobot's own choice, for exact random access),
each episode encoded on its own and the episodes' packets joined (:mod:`robocfg.datasets.video`),
so shards written by several workers merge into the very bytes one process would write
(:mod:`robocfg.datasets.shards`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from robocfg.datasets.episode import DatasetLayout, EpisodeRecord
from robocfg.datasets.files import FileLimits, FileSeries
from robocfg.datasets.lerobot_meta import write_episodes, write_json, write_table, write_tasks
from robocfg.datasets.stats import DepthStats, ImageStats, vector_stats
from robocfg.datasets.video import EncodedVideo, VideoConcat, encode_episode

CODEBASE_VERSION = "v3.0"
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
VIDEO_PATH = "videos/{video_key}/chunk-{chunk_index:03d}/file-{file_index:03d}.mp4"
ROW_GROUP_BYTES = 32 << 20  # frame data buffered before it is written as one parquet row group
STATE, ENV, ACTION = "observation.state", "observation.environment_state", "action"
ACTION_JOINT, ACTION_EE = "action.joint", "action.ee_delta"  # the second action feature (--dataset-actions)


def image_key(camera: str) -> str:
    return f"observation.images.{camera}"


def depth_key(camera: str) -> str:
    return f"observation.depth.{camera}"


def vector_names(layout: DatasetLayout) -> dict[str, tuple[str, ...]]:
    """Feature key → entry names of the float vectors stored, in column order: no environment
    state when the episodes have no object (e.g. a trajectory run); ``action`` is the joint
    targets, or with ``--dataset-actions ee_delta`` the EE deltas (the joint targets then in
    ``action.joint``); ``both`` adds ``action.ee_delta``."""
    from robocfg.datasets.episode import EE_DELTA_NAMES

    names = {STATE: layout.state_names, ENV: layout.env_state_names}
    if layout.actions == "ee_delta":
        names |= {ACTION: EE_DELTA_NAMES, ACTION_JOINT: layout.action_names}
    else:
        names |= {ACTION: layout.action_names}
        if layout.actions == "both":
            names |= {ACTION_EE: EE_DELTA_NAMES}
    return {k: v for k, v in names.items() if v or k != ENV}


def vector_dims(layout: DatasetLayout) -> dict[str, int]:
    """Feature key → width of the float vectors stored (:func:`vector_names`)."""
    return {k: len(v) for k, v in vector_names(layout).items()}


def joint_action_key(layout_actions: str) -> str:
    """The feature holding the joint-target actions (what replay drives with)."""
    return ACTION_JOINT if layout_actions == "ee_delta" else ACTION


class LeRobotWriter:
    """Add episodes one by one (videos are encoded as they come), then ``close()``; ``limits``:
    when data and video files roll over (lerobot's defaults)."""

    def __init__(self, root: Path, layout: DatasetLayout, extra_info: dict, limits: FileLimits | None = None):
        self.root, self.layout, self.extra_info = Path(root), layout, extra_info
        self.limits = limits = limits or FileLimits()
        self.root.mkdir(parents=True, exist_ok=True)
        self.columns: dict[str, list[np.ndarray]] = {k: [] for k in (STATE, ENV, ACTION, ACTION_JOINT, ACTION_EE,
                                                                     "phase_index", "episode_index", "frame_index",
                                                                     "task_index")}
        self.episodes: list[dict] = []
        self.tasks: dict[str, int] = {}
        self.frames = 0
        self._data = FileSeries(limits.data_files_size_in_mb, limits.chunks_size)
        self._video_files = {c.name: FileSeries(limits.video_files_size_in_mb, limits.chunks_size)
                             for c in layout.cameras}
        self.videos = {c.name: VideoConcat(self._video_path(c.name), layout.fps) for c in layout.cameras}
        self.image_stats = {c.name: ImageStats() for c in layout.cameras}
        self.depth_stats = {c.name: DepthStats() for c in layout.cameras if c.depth}
        self._pending: list[pa.Table] = []  # episodes' data rows not yet written
        self._pending_bytes = 0
        self._parquet: pq.ParquetWriter | None = None

    def add(self, ep: EpisodeRecord) -> None:
        """Append an episode with its raw images (encoded here, one segment per camera)."""
        for name in self.videos:
            self.image_stats[name].add(ep.images[name])
        self.add_encoded(ep, {name: encode_episode(ep.images[name], self.layout.fps) for name in self.videos})

    def add_encoded(self, ep: EpisodeRecord, videos: dict[str, EncodedVideo]) -> None:
        """Append an episode whose camera frames are already encoded (``ep.images`` is not read;
        their statistics come separately, :meth:`add_image_histograms`); depth from ``ep.depth``."""
        n, k = ep.length, len(self.episodes)
        depth = {name: np.asarray(ep.depth[name], np.float32) for name in self.depth_stats}
        for name, d in depth.items():
            self.depth_stats[name].add(d)
        task_index = self.tasks.setdefault(ep.language, len(self.tasks))
        cols: dict[str, np.ndarray] = {}
        for key, arr in ((STATE, ep.state), (ENV, ep.env_state), ("phase_index", ep.phase), *self._actions(ep)):
            cols[key] = arr
        cols["episode_index"] = np.full(n, k, np.int64)
        cols["frame_index"] = np.arange(n, dtype=np.int64)
        cols["task_index"] = np.full(n, task_index, np.int64)
        for key, arr in cols.items():
            self.columns[key].append(arr)
        rows = self._rows(cols, depth, self.frames, n)
        if self._data.rolls(rows.nbytes):  # the episode starts the next data file
            self._end_data_file()
        self._data.add(rows.nbytes)
        self._add_rows(rows)
        row = {"episode_index": k, "tasks": [ep.language], "length": n,
               "data/chunk_index": self._data.chunk, "data/file_index": self._data.file,
               "dataset_from_index": self.frames, "dataset_to_index": self.frames + n}
        for name in self.videos:
            key, files = image_key(name), self._video_files[name]
            if files.add(len(videos[name].data)):  # the episode starts the camera's next video file
                self.videos[name].close()
                self.videos[name] = VideoConcat(self._video_path(name), self.layout.fps)
            t0 = self.videos[name].frames / self.layout.fps
            self.videos[name].append(videos[name])
            row |= {f"videos/{key}/chunk_index": files.chunk, f"videos/{key}/file_index": files.file,
                    f"videos/{key}/from_timestamp": t0, f"videos/{key}/to_timestamp": t0 + n / self.layout.fps}
        row |= {"meta/episodes/chunk_index": 0, "meta/episodes/file_index": 0,  # set by close()
                "success": ep.success, "failed_phase": ep.failed_phase, "reason": ep.reason, "seed": ep.seed,
                "run_episode": ep.index, "physics_steps": ep.physics_steps, "object_final": ep.object_final}
        self.episodes.append(row)
        self.frames += n

    def _rows(self, cols: dict[str, np.ndarray], depth: dict[str, np.ndarray], first: int, n: int) -> pa.Table:
        """The data rows of ``n`` frames (dataset indices ``first`` on): ``cols`` the vector and
        index columns, ``depth`` camera → (n, H, W) m."""
        fps = self.layout.fps
        arrays = {key: _fixed_list(np.asarray(cols[key]).reshape(n, d), d) for key, d in vector_dims(self.layout).items()}
        arrays |= {
            "timestamp": pa.array((cols["frame_index"] / fps).astype(np.float32)),
            "frame_index": pa.array(cols["frame_index"].astype(np.int64)),
            "episode_index": pa.array(cols["episode_index"].astype(np.int64)),
            "index": pa.array(np.arange(first, first + n, dtype=np.int64)),
            "task_index": pa.array(cols["task_index"].astype(np.int64)),
            "phase_index": pa.array(cols["phase_index"].astype(np.int64)),
        }
        for c in self.layout.cameras:
            if c.depth:
                arrays[depth_key(c.name)] = _fixed_list(depth[c.name].reshape(n, c.height, c.width), c.width, c.height)
        return pa.table(arrays)

    def _video_path(self, camera: str) -> Path:
        """The camera's current video file."""
        f = self._video_files[camera]
        return self.root / VIDEO_PATH.format(video_key=image_key(camera), chunk_index=f.chunk, file_index=f.file)

    def _add_rows(self, rows: pa.Table) -> None:
        """Buffer an episode's rows; write the buffer as a row group once it holds ``ROW_GROUP_BYTES``."""
        self._pending.append(rows)
        self._pending_bytes += rows.nbytes
        if self._pending_bytes >= ROW_GROUP_BYTES:
            self._flush()

    def _flush(self) -> None:
        if not self._pending:
            return
        table = pa.concat_tables(self._pending).combine_chunks()
        self._pending, self._pending_bytes = [], 0
        if self._parquet is None:
            path = self.root / DATA_PATH.format(chunk_index=self._data.chunk, file_index=self._data.file)
            path.parent.mkdir(parents=True, exist_ok=True)
            self._parquet = pq.ParquetWriter(path, table.schema)
        self._parquet.write_table(table)

    def _end_data_file(self) -> None:
        """Write the buffered rows to the current data file and close it."""
        self._flush()
        if self._parquet is not None:
            self._parquet.close()
            self._parquet = None

    def _actions(self, ep: EpisodeRecord) -> list[tuple[str, np.ndarray]]:
        """(feature key, (T, D) array) of the episode's actions as the layout stores them."""
        mode = self.layout.actions
        if mode == "joint":
            return [(ACTION, ep.action)]
        if ep.ee_delta is None:
            raise ValueError("the layout stores EE-delta actions but the episode has none")
        if mode == "ee_delta":
            return [(ACTION, ep.ee_delta), (ACTION_JOINT, ep.action)]
        return [(ACTION, ep.action), (ACTION_EE, ep.ee_delta)]

    def add_image_histograms(self, stats: dict[str, ImageStats]) -> None:
        """Add the colour histograms of episodes given by :meth:`add_encoded` (integer counts, so
        the sum is the same in any order)."""
        for name, s in stats.items():
            self.image_stats[name].hist += s.hist
            self.image_stats[name].frames += s.frames

    def close(self) -> Path:
        """Write the parquet files and metadata; returns the dataset root."""
        for v in self.videos.values():
            v.close()
        if self._parquet is not None or self._pending:
            self._end_data_file()
        else:  # no episode: the columns with no row
            empty = {k: np.zeros(0) for k in self.columns}
            depth = {c.name: np.zeros((0, c.height, c.width)) for c in self.layout.cameras if c.depth}
            write_table(self._rows(empty, depth, 0, 0), self.root / DATA_PATH.format(chunk_index=0, file_index=0))
        cols = {k: np.concatenate(v) if v else np.zeros(0) for k, v in self.columns.items()}
        n = self.frames
        dims = vector_dims(self.layout)
        write_episodes(self.root, self.episodes, self.limits)
        write_tasks(self.tasks, self.root / "meta/tasks.parquet")
        stats = {key: vector_stats(cols[key].reshape(n, d)) for key, d in dims.items()} if n else {}
        if n:
            scalars = {"timestamp": (cols["frame_index"] / self.layout.fps).astype(np.float32),
                       "index": np.arange(n, dtype=np.int64)}
            for key in ("timestamp", "frame_index", "episode_index", "index", "task_index", "phase_index"):
                stats[key] = vector_stats(scalars[key] if key in scalars else cols[key].astype(np.int64))
            stats |= {image_key(c): s.result() for c, s in self.image_stats.items()}
            stats |= {depth_key(c): s.result() for c, s in self.depth_stats.items()}
        write_json(self.root / "meta/stats.json", stats)
        write_json(self.root / "meta/info.json", self._info())
        return self.root

    def _info(self) -> dict:
        lay = self.layout
        scalar: dict = {"dtype": "int64", "shape": [1], "names": None}
        features: dict[str, dict] = {key: {"dtype": "float32", "shape": [len(names)], "names": list(names)}
                                     for key, names in vector_names(lay).items()}
        for c in lay.cameras:
            features[image_key(c.name)] = {
                "dtype": "video", "shape": [c.height, c.width, 3], "names": ["height", "width", "channels"],
                "info": {"video.height": c.height, "video.width": c.width, "video.codec": "h264",
                         "video.pix_fmt": "yuv420p", "video.is_depth_map": False, "video.fps": lay.fps,
                         "video.channels": 3, "has_audio": False}}
            if c.depth:
                features[depth_key(c.name)] = {"dtype": "float32", "shape": [c.height, c.width],
                                               "names": ["height", "width"]}
        features |= {"timestamp": {"dtype": "float32", "shape": [1], "names": None}, "frame_index": scalar,
                     "episode_index": scalar, "index": scalar, "task_index": scalar, "phase_index": scalar}
        return {
            "codebase_version": CODEBASE_VERSION, "robot_type": lay.robot,
            "total_episodes": len(self.episodes), "total_frames": self.frames, "total_tasks": len(self.tasks),
            **self.limits.info(), "fps": lay.fps,
            "splits": {"train": f"0:{len(self.episodes)}"}, "data_path": DATA_PATH,
            "video_path": VIDEO_PATH if lay.cameras else None, "features": features,
            "robocfg": {"phases": list(lay.phases), "task_name": lay.task_name, "actions": lay.actions, **self.extra_info,
                        **({"depth": DEPTH_NOTE} if any(c.depth for c in lay.cameras) else {})},
        }


DEPTH_NOTE = ("observation.depth.<camera>: float32 (H, W), metres along the camera's optical axis, "
              "stored exactly in the data parquet; stats over all pixels")


def _fixed_list(x: np.ndarray, d: int, rows: int | None = None) -> pa.Array:
    """Float32 values as fixed-size lists of ``d`` (and, with ``rows``, lists of ``rows`` of those:
    an (N, rows, d) array, read by ``datasets`` as an Array2D)."""
    a = pa.FixedSizeListArray.from_arrays(pa.array(np.asarray(x, np.float32).reshape(-1)), d)
    return a if rows is None else pa.FixedSizeListArray.from_arrays(a, rows)
