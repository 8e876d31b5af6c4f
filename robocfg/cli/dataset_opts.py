"""The dataset sink a ``run`` command records into (its ``--dataset*`` options are the kind's)."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import typer


def dataset_sink(path: Path | None, fmt: str, fps: int, keep: str, task, seed: int, arm: str | None,
                 robot: str | None, language: str):
    """The sink recording a run into ``path`` (None: no dataset). Bad choices are user errors."""
    if path is None:
        return None
    from robocfg.datasets.sink import DatasetSink
    from robocfg.errors import RobocfgError

    if fmt not in ("lerobot", "hdf5"):
        raise typer.BadParameter(f"{fmt!r}: choose lerobot or hdf5", param_hint="--dataset-format")
    if keep not in ("success", "all"):
        raise typer.BadParameter(f"{keep!r}: choose success or all", param_hint="--keep")
    from robocfg.datasets.recorder import steps_per_frame

    steps_per_frame(task.config.sim.timestep, fps)  # the rate must divide the physics rate
    if fmt == "lerobot" and any(c.depth for c in task.config.cameras):
        raise RobocfgError("depth images are written to --dataset-format hdf5 only; "
                           "set 'depth: false' on the task's cameras for lerobot")
    if path.exists() and any(path.iterdir()):
        raise RobocfgError(f"--dataset {path}: the directory exists and is not empty; choose a new one")
    fmt_l: Literal["lerobot", "hdf5"] = "lerobot" if fmt == "lerobot" else "hdf5"
    keep_l: Literal["success", "all"] = "all" if keep == "all" else "success"
    info = {"task_path": str(Path(task.path).resolve()), "robot_override": robot, "seed": seed, "arm": arm, "keep": keep}
    return DatasetSink(path, fmt_l, task, fps=fps, keep=keep_l, language=language, extra_info=info)
