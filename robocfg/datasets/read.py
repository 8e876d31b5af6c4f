"""Read back a dataset robocfg wrote (LeRobot v3.0 directory or robomimic HDF5) with pyarrow/h5py:
summary figures for ``robocfg dataset info`` and one episode's actions and outcome for replay."""

from __future__ import annotations

import json
from dataclasses import dataclass
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


def _h5_path(root: Path) -> Path:
    return root if root.is_file() else root / "data.hdf5"


def read_info(root: Path) -> DatasetInfo:
    root = Path(root)
    if dataset_format(root) == "lerobot":
        import pyarrow.parquet as pq

        info = json.loads((root / "meta/info.json").read_text())
        eps = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()
        shapes = {k: list(v["shape"]) for k, v in info["features"].items()}
        run = info.get("robocfg", {})
        return DatasetInfo(str(root), "lerobot", info["fps"], info.get("robot_type") or "", info["total_episodes"],
                           info["total_frames"], sum(bool(e.get("success")) for e in eps), shapes, run)
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

        from robocfg.datasets.lerobot import joint_action_key

        e = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pylist()[k]
        key = joint_action_key(read_info(root).run.get("actions", "joint"))
        data = pq.read_table(root / "data/chunk-000/file-000.parquet", columns=["episode_index", "frame_index", key])
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
