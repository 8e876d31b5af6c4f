"""The dataset sink a ``run`` command records into: every kind whose ``Options`` subclass
:class:`robocfg.engine.dataset.DatasetOptions` (pick-place, pick-place-many, grasp, trajectory) gets the
``--dataset*`` options, and :data:`DATASET_HOOK` turns them into a sink before the run and closes
it (printing its summary) after."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any, Literal

import typer

from robocfg.cli.run_command import CliHook


def dataset_sink(path: Path | None, fmt: str, fps: int, keep: str, task, seed: int, arm: str | None,
                 robot: str | None, language: str, renderer: str = "auto", actions: str = "joint",
                 files: tuple[float, float, int] = (100.0, 200.0, 1000)):
    """The sink recording a run into ``path`` (None: no dataset); ``files``: a LeRobot dataset's
    data and video file limits (MB) and files per chunk. Bad choices are user errors."""
    if path is None:
        return None
    from robocfg.datasets.episode import Actions
    from robocfg.datasets.files import MAX_CHUNKS_SIZE, FileLimits
    from robocfg.datasets.sink import DatasetSink
    from robocfg.errors import RobocfgError

    if fmt not in ("lerobot", "hdf5"):
        raise typer.BadParameter(f"{fmt!r}: choose lerobot or hdf5", param_hint="--dataset-format")
    if keep not in ("success", "all"):
        raise typer.BadParameter(f"{keep!r}: choose success or all", param_hint="--keep")
    modes: dict[str, Actions] = {"joint": "joint", "ee_delta": "ee_delta", "both": "both"}
    if actions not in modes:
        raise typer.BadParameter(f"{actions!r}: choose one of {', '.join(modes)}", param_hint="--dataset-actions")
    from robocfg.datasets.recorder import steps_per_frame

    steps_per_frame(task.config.sim.timestep, fps)  # the rate must divide the physics rate
    data_mb, video_mb, chunk_files = files
    for flag, value, ok, must in (("--dataset-data-mb", data_mb, data_mb > 0, "a positive size"),
                                  ("--dataset-video-mb", video_mb, video_mb > 0, "a positive size"),
                                  ("--dataset-chunk-files", chunk_files, 1 <= chunk_files <= MAX_CHUNKS_SIZE,
                                   f"1..{MAX_CHUNKS_SIZE} (three-digit file names)")):
        if not ok:
            raise typer.BadParameter(f"{value:g}: must be {must}", param_hint=flag)
    limits = FileLimits(chunk_files, data_mb, video_mb)
    if path.exists() and any(path.iterdir()):
        raise RobocfgError(f"--dataset {path}: the directory exists and is not empty; choose a new one")
    fmt_l: Literal["lerobot", "hdf5"] = "lerobot" if fmt == "lerobot" else "hdf5"
    keep_l: Literal["success", "all"] = "all" if keep == "all" else "success"
    info = {"task_path": str(Path(task.path).resolve()), "robot_override": robot, "seed": seed, "arm": arm, "keep": keep}
    from robocfg.sim.camera_rig import Renderer

    renderers: dict[str, Renderer] = {"auto": "auto", "tiny": "tiny", "exact": "exact", "egl": "egl"}
    if renderer not in renderers:
        raise typer.BadParameter(f"{renderer!r}: choose one of {', '.join(renderers)}", param_hint="--dataset-renderer")
    return DatasetSink(path, fmt_l, task, fps=fps, keep=keep_l, language=language, extra_info=info,
                       renderer=renderers[renderer], actions=modes[actions], limits=limits)


def _prepare(task: Any, options: Any, robot: str | None) -> Any:
    from robocfg.engine.dataset import DatasetOptions

    x = options.extras
    if not isinstance(x, DatasetOptions) or x.dataset is None:
        return options
    seed = options.resolved_seed(task.config.sim.seed)
    sink = dataset_sink(x.dataset, x.dataset_format, x.dataset_fps, x.keep, task, seed, options.arm, robot, "",
                        x.dataset_renderer, x.dataset_actions, (x.dataset_data_mb, x.dataset_video_mb, x.dataset_chunk_files))
    return dataclasses.replace(options, sink=sink)


def _finish(options: Any, report: Any) -> list[str]:
    if options.sink is None:
        return []
    written = options.sink.close()
    return [f"dataset ({written.format}): {written.episodes_kept}/{written.episodes_run} episodes kept, "
            f"{written.frames} frames → {written.path}"]


DATASET_HOOK = CliHook(_prepare, _finish)  # the kind gives each episode's instruction (language)
