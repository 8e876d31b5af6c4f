"""Options and helpers shared by every command (defined once)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Annotated, Any

import typer

JsonOpt = Annotated[Path | None, typer.Option("--json", help="Write a JSON report to this path.", dir_okay=False)]
QuietOpt = Annotated[bool, typer.Option("--quiet", "-q", help="Print only the result.")]
StrictOpt = Annotated[bool, typer.Option("--strict", help="Treat warnings as errors.")]
RobotOpt = Annotated[str | None, typer.Option("--robot", "-r", help="Robot name or YAML path (replaces the task's first robot).")]
GuiOpt = Annotated[bool, typer.Option("--gui", help="Open the PyBullet GUI instead of running headless.")]
RecordOpt = Annotated[Path | None, typer.Option("--record", help="Save pictures: .gif or .mp4 (animation), .png (last frame), *sheet.png (key frame per phase).", dir_okay=False)]
SeedOpt = Annotated[int | None, typer.Option("--seed", min=0, help="Random seed, >= 0 (overrides the task's sim.seed).")]


def debug_enabled() -> bool:
    return os.environ.get("ROBOCFG_DEBUG", "") not in ("", "0")


def console(stderr: bool = False):
    import sys

    from rich.console import Console

    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else 160
    return Console(stderr=stderr, highlight=False, soft_wrap=True, width=width)


def write_json(path: Path | None, payload: Any) -> None:
    """Write ``payload`` (a pydantic model, dataclass or plain data) as indented JSON."""
    if path is None:
        return
    if hasattr(payload, "model_dump"):
        payload = payload.model_dump(mode="json")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(payload, indent=2, sort_keys=False, default=_default) + "\n")


def _default(o: Any) -> Any:
    import dataclasses

    if dataclasses.is_dataclass(o):
        return dataclasses.asdict(o)  # type: ignore[arg-type]
    if hasattr(o, "tolist"):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def load_task_for(task: str, kind: str, command: str, robot: str | None = None):
    """Find and check a task YAML by name or path; it must be a ``task: <kind>`` file."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.errors import ConfigError

    checked = load_task(catalog.find("tasks", task), robot_override=robot)
    if checked.config.task != kind:
        raise ConfigError([checked.doc.problem(("task",), f"'run {command}' needs a 'task: {kind}' file, "
                                                         f"this is 'task: {checked.config.task}'")])
    return checked


def run_and_report(run, json_path: Path | None, quiet: bool, full, one_line) -> int:
    """Call ``run()``; write its result as JSON (also the partial report of a failed run) and print
    it: ``one_line(result)`` with ``-q``, ``full(result)`` otherwise. A failure is re-raised."""
    from robocfg.errors import RunFailed

    try:
        result = run()
    except RunFailed as exc:
        if exc.report is not None:
            write_json(json_path, exc.report)
            if not quiet:
                full(exc.report)
        raise
    write_json(json_path, result)
    if quiet:
        console().print(one_line(result), markup=False)
    else:
        full(result)
    return 0


def key_value_table(title: str, rows: list[tuple[str, str]]):
    """A two-column rich table (no header) of ``(key, value)`` rows."""
    from rich.table import Table

    table = Table(title=title, show_header=False)
    table.add_column("key")
    table.add_column("value")
    for k, v in rows:
        table.add_row(k, v)
    return table
