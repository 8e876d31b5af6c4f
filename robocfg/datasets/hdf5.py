"""A robomimic-layout HDF5 dataset writer (h5py).

``data/demo_<i>/`` per kept episode: ``actions`` (T, A), ``obs/<key>`` (``robot_state``,
``object_state``, ``<camera>_image`` (T, H, W, 3) uint8, ``<camera>_depth`` (T, H, W) float32 m),
``states`` (T, S) — robot and object state side by side (robocfg re-simulates from the task and
seed, not from these), ``rewards`` (1 on the last frame of a successful episode, else 0),
``dones`` (1 on the last frame). Attributes: ``data.total`` (frames), ``data.env_args`` (JSON:
env name, type, the task), per demo ``num_samples`` and robocfg's outcome. With
``--dataset-actions both`` the EE-delta actions are ``actions_ee_delta`` beside ``actions``; with
``ee_delta`` they are ``actions`` and the joint targets ``actions_joint`` (what replay drives with). ``mask/train`` and
``mask/valid`` split the demo names 90/10 (every tenth demo is validation).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from robocfg.datasets.episode import EE_DELTA_NAMES, DatasetLayout, EpisodeRecord

FILE_NAME = "data.hdf5"


class Hdf5Writer:
    """Add episodes one by one, then ``close()``; the file is ``<root>/data.hdf5``."""

    def __init__(self, root: Path, layout: DatasetLayout, extra_info: dict):
        import h5py

        self.root, self.layout = Path(root), layout
        self.root.mkdir(parents=True, exist_ok=True)
        self.file = h5py.File(self.root / FILE_NAME, "w")
        self.data = self.file.create_group("data")
        self.total = 0
        self.names: list[str] = []
        self.data.attrs["env_args"] = json.dumps({
            "env_name": layout.task_name, "type": "robocfg", "env_kwargs": {
                "robot": layout.robot, "fps": layout.fps, "phases": list(layout.phases),
                "state_names": list(layout.state_names), "object_state_names": list(layout.env_state_names),
                "action_names": list(layout.action_names), "actions": layout.actions,
                **({"ee_delta_names": list(EE_DELTA_NAMES)} if layout.ee_delta else {}), **extra_info}})

    def add(self, ep: EpisodeRecord) -> None:
        name = f"demo_{len(self.names)}"
        g = self.data.create_group(name)
        n = ep.length
        g.attrs.update({"num_samples": n, "success": ep.success, "failed_phase": ep.failed_phase or "",
                        "reason": ep.reason, "seed": ep.seed, "run_episode": ep.index, "language": ep.language,
                        "physics_steps": ep.physics_steps, "object_final": np.asarray(ep.object_final)})
        mode = self.layout.actions
        if mode != "joint" and ep.ee_delta is None:
            raise ValueError("the layout stores EE-delta actions but the episode has none")
        g.create_dataset("actions", data=ep.ee_delta if mode == "ee_delta" else ep.action)
        if mode == "ee_delta":
            g.create_dataset("actions_joint", data=ep.action)
        elif mode == "both":
            g.create_dataset("actions_ee_delta", data=ep.ee_delta)
        g.create_dataset("states", data=np.concatenate([ep.state, ep.env_state], axis=1))
        rewards = np.zeros(n, np.float32)
        dones = np.zeros(n, np.int64)
        dones[-1] = 1
        rewards[-1] = float(ep.success)
        g.create_dataset("rewards", data=rewards)
        g.create_dataset("dones", data=dones)
        g.create_dataset("phase", data=ep.phase)
        obs = g.create_group("obs")
        obs.create_dataset("robot_state", data=ep.state)
        obs.create_dataset("object_state", data=ep.env_state)
        for cam, frames in ep.images.items():
            obs.create_dataset(f"{cam}_image", data=frames, compression="gzip", compression_opts=4,
                               chunks=(1, *frames.shape[1:]))
        for cam, depth in ep.depth.items():
            obs.create_dataset(f"{cam}_depth", data=depth, compression="gzip", compression_opts=4,
                               chunks=(1, *depth.shape[1:]))
        self.total += n
        self.names.append(name)

    def close(self) -> Path:
        self.data.attrs["total"] = self.total
        mask = self.file.create_group("mask")
        valid = [n for i, n in enumerate(self.names) if i % 10 == 9]
        train = [n for i, n in enumerate(self.names) if i % 10 != 9]
        mask.create_dataset("train", data=np.array(train, dtype="S"))
        mask.create_dataset("valid", data=np.array(valid, dtype="S"))
        self.file.close()
        return self.root / FILE_NAME
