"""Read back a dataset robocfg wrote (LeRobot v3.0 directory or robomimic HDF5) with pyarrow/h5py:
summary figures for ``robocfg dataset info`` and one episode's actions and outcome for replay."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from robocfg.errors import RobocfgError


@dataclass(frozen=True)
class EpisodeMeta:
    """A stored episode: its run's episode index and seed, outcome, physics steps, the object's
    final world pose (position m, quaternion x y z w) and the recorded joint-target actions (T, A)."""

    dataset_index: int
    run_episode: int
    seed: int
    success: bool
    failed_phase: str | None
    reason: str
    physics_steps: int
    object_final: list[float]
    actions: np.ndarray


@dataclass(frozen=True)
class DatasetInfo:
    """Figures of a dataset: format, fps, episodes, frames, successes, feature name → shape, and
    the run facts (task path, robot, arm) stored in its metadata."""

    path: str
    format: str
    fps: int
    robot: str
    episodes: int
    frames: int
    successes: int
    features: dict[str, list[int]]
    run: dict
    files: dict[str, int] = field(default_factory=dict)  # LeRobot: files per series (data, meta/episodes, each video key)

    @property
    def success_rate(self) -> float:
        return self.successes / self.episodes if self.episodes else 0.0


def dataset_format(root: Path) -> str:
    root = Path(root)
    if (root / "meta" / "info.json").is_file():
        return "lerobot"
    if (root / "data.hdf5").is_file() or (root.is_file() and root.suffix in (".hdf5", ".h5")):
        return "hdf5"
    raise RobocfgError(f"{root}: not a robocfg dataset (no meta/info.json, no data.hdf5)")


def _file_counts(root: Path) -> dict[str, int]:
    """A LeRobot dataset's number of files in each series: ``data``, ``meta/episodes``, ``videos/<key>``."""
    from robocfg.datasets.files import series_files

    counts = {"data": len(series_files(root / "data")),
              "meta/episodes": len(series_files(root / "meta/episodes"))}
    videos = root / "videos"
    if videos.is_dir():
        counts |= {f"videos/{d.name}": len(series_files(d, "mp4")) for d in sorted(videos.iterdir()) if d.is_dir()}
    return counts


def _h5_path(root: Path) -> Path:
    return root if root.is_file() else root / "data.hdf5"


def read_info(root: Path) -> DatasetInfo:
    root = Path(root)
    if dataset_format(root) == "lerobot":
        from robocfg.datasets.lerobot_meta import read_episodes

        info = json.loads((root / "meta/info.json").read_text())
        eps = read_episodes(root)
        successes = sum(bool(s) for s in eps["success"].to_pylist()) if "success" in eps.column_names else 0
        shapes = {k: list(v["shape"]) for k, v in info["features"].items()}
        run = info.get("robocfg", {})
        return DatasetInfo(str(root), "lerobot", info["fps"], info.get("robot_type") or "", info["total_episodes"],
                           info["total_frames"], successes, shapes, run, _file_counts(root))
    import h5py

    with h5py.File(_h5_path(root), "r") as f:
        env = json.loads(f["data"].attrs["env_args"])["env_kwargs"]
        demos = list(f["data"].keys())
        feats: dict[str, list[int]] = {}
        if demos:
            d0 = f["data"][demos[0]]
            feats["actions"] = [d0["actions"].shape[1]]
            feats |= {f"obs/{k}": list(v.shape[1:]) for k, v in d0["obs"].items()}
        succ = sum(bool(f["data"][d].attrs["success"]) for d in demos)
        return DatasetInfo(str(root), "hdf5", env["fps"], env["robot"], len(demos), int(f["data"].attrs["total"]),
                           succ, feats, env)


def read_episode(root: Path, k: int) -> EpisodeMeta:
    """Stored episode ``k`` (0-based position in the dataset)."""
    root = Path(root)
    n = read_info(root).episodes
    if not 0 <= k < n:
        raise RobocfgError(f"--episode {k}: the dataset has {n} episode(s) (0..{n - 1})")
    if dataset_format(root) == "lerobot":
        import pyarrow.compute as pc
        import pyarrow.parquet as pq

        from robocfg.datasets.lerobot import DATA_PATH, joint_action_key
        from robocfg.datasets.lerobot_meta import read_episodes

        e = read_episodes(root).slice(k, 1).to_pylist()[0]
        key = joint_action_key(read_info(root).run.get("actions", "joint"))
        path = root / DATA_PATH.format(chunk_index=e["data/chunk_index"], file_index=e["data/file_index"])
        data = pq.read_table(path, columns=["episode_index", "frame_index", key])  # the file holding episode k
        rows = data.filter(pc.equal(data["episode_index"], k))
        actions = np.asarray(rows[key].to_pylist(), np.float64)[np.argsort(rows["frame_index"].to_numpy())]
        return EpisodeMeta(k, e["run_episode"], e["seed"], bool(e["success"]), e["failed_phase"], e["reason"],
                           e["physics_steps"], list(e["object_final"]), actions)
    import h5py

    with h5py.File(_h5_path(root), "r") as f:
        g = f["data"][f"demo_{k}"]
        a = g.attrs
        joint = "actions_joint" if "actions_joint" in g else "actions"
        return EpisodeMeta(k, int(a["run_episode"]), int(a["seed"]), bool(a["success"]), str(a["failed_phase"]) or None,
                           str(a["reason"]), int(a["physics_steps"]), [float(v) for v in a["object_final"]],
                           np.asarray(g[joint][()], np.float64))
