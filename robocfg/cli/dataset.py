"""``robocfg dataset info|replay DIR``: inspect a recorded dataset; re-simulate an episode from its actions."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import JsonOpt, console, key_value_table, write_json

dataset_app = typer.Typer(help="Inspect and replay datasets written by `run ... --dataset`.", no_args_is_help=True)
DirArg = Annotated[Path, typer.Argument(help="Dataset directory (LeRobot v3.0) or directory/file of an HDF5 dataset.")]


@dataset_app.command("info")
def info(path: DirArg, json_path: JsonOpt = None) -> int:
    """Summarise a dataset. Episodes, frames, features (name and shape), success rate and (LeRobot) files per series."""
    from robocfg.datasets.read import read_info

    d = read_info(path)
    write_json(json_path, {"path": d.path, "format": d.format, "fps": d.fps, "robot": d.robot, "episodes": d.episodes,
                           "frames": d.frames, "successes": d.successes, "success_rate": d.success_rate,
                           "features": d.features, **({"files": d.files} if d.files else {})})
    rows = [("format", d.format), ("robot", d.robot), ("fps", str(d.fps)), ("episodes", str(d.episodes)),
            ("frames", str(d.frames)), ("success", f"{d.successes}/{d.episodes} ({d.success_rate:.1%})")]
    rows += [(f"feature {k}", "×".join(map(str, v)) or "scalar") for k, v in d.features.items()]
    rows += [(f"files {series}", str(n)) for series, n in d.files.items()]  # LeRobot: files rolled over at the size limits
    console().print(key_value_table(f"dataset {d.path}", rows))
    return 0


@dataset_app.command("replay")
def replay(path: DirArg,
           episode: Annotated[int, typer.Option("--episode", "-e", min=0, help="Episode position in the dataset (0-based).")] = 0,
           json_path: JsonOpt = None) -> int:
    """Re-simulate one episode from its recorded actions. Exit 0 when the outcome matches (same
    success, object final position within 1 mm), 1 otherwise."""
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.datasets.replay import replay_episode

    r = replay_episode(path, episode)
    write_json(json_path, {"episode": r.episode, "matches": r.matches, "recorded_success": r.recorded_success,
                           "replayed_success": r.replayed_success, "replayed_reason": r.replayed_reason,
                           "recorded_object": r.recorded_object, "replayed_object": r.replayed_object,
                           "distance": r.distance, "tolerance": r.tolerance})
    rows = [("success (recorded / replayed)", f"{r.recorded_success} / {r.replayed_success}"),
            ("replay outcome", r.replayed_reason),
            ("object final distance", f"{r.distance * 1000:.3f} mm (tolerance {r.tolerance * 1000:.1f} mm)")]
    out = console()
    out.print(key_value_table(f"dataset replay: episode {r.episode}", rows))
    out.print("[green]matches[/green]" if r.matches else "[red]does not match[/red]")
    return 0 if r.matches else 1
