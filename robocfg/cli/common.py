"""Options and helpers shared by every command (defined once)."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Annotated, Any

import typer

from robocfg.cli.completion import robot_names

STDOUT = Path("-")  # ``--json -``: the report goes to standard output, the human summary to stderr
_stdout_taken = False


def _output_path(raw: str, option: str, suffixes: tuple[str, ...]) -> Path:
    """Check an output path when the command line is parsed, i.e. before any simulation: its
    folder exists and is writable, it is no folder itself (``out/`` included), it ends in one of
    ``suffixes``. ``-`` (only for ``--json``) is standard output."""
    global _stdout_taken
    if raw == "-" and option == "--json":
        _stdout_taken = True
        return STDOUT
    path = Path(raw)
    if raw.endswith(("/", os.sep)) or path.is_dir():
        raise typer.BadParameter(f"{raw!r} is a folder; give a file name", param_hint=option)
    if suffixes and path.suffix.lower() not in suffixes:
        raise typer.BadParameter(f"{raw!r} must end in {' or '.join(suffixes)}", param_hint=option)
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise typer.BadParameter(f"folder {str(parent)!r} does not exist", param_hint=option)
    if not _can_create_in(parent) or (path.exists() and not os.access(path, os.W_OK)):
        raise typer.BadParameter(f"{raw!r} is not writable", param_hint=option)
    return path


def _can_create_in(folder: Path) -> bool:
    """Whether a file can be created in ``folder`` (tried, since permission bits do not tell for
    root or for special file systems); the report is later written there the same way."""
    import tempfile

    try:
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def _json_path(raw: str) -> Path:
    return _output_path(raw, "--json", (".json",))


def _record_path(raw: str) -> Path:
    return _output_path(raw, "--record", (".gif", ".mp4", ".png"))


JsonOpt = Annotated[Path | None, typer.Option("--json", parser=_json_path, metavar="PATH",
                                              help="Write a JSON report to this .json file ('-': standard output).")]
QuietOpt = Annotated[bool, typer.Option("--quiet", "-q", help="Print only the result.")]
StrictOpt = Annotated[bool, typer.Option("--strict", help="Treat warnings as errors.")]
RobotOpt = Annotated[str | None, typer.Option("--robot", "-r", autocompletion=robot_names,
                                              help="Robot name or YAML path (replaces the task's first robot).")]
GuiOpt = Annotated[bool, typer.Option("--gui", help="Open the PyBullet GUI instead of running headless.")]
RecordOpt = Annotated[Path | None, typer.Option("--record", parser=_record_path, metavar="PATH",
                                                help="Save pictures: .gif or .mp4 (animation), .png (last frame), "
                                                     "*sheet.png (key frame per phase).")]
SeedOpt = Annotated[int | None, typer.Option("--seed", min=0, help="Random seed, >= 0 (overrides the task's sim.seed).")]


_debug_flag = False  # set by ``--debug`` for this command line only (see ``set_debug``)


def set_debug(on: bool) -> None:
    """Show tracebacks for the command line being run. A flag in this module, not an environment
    variable: ``--debug`` given to one in-process call (``app([...])``, the Python API's tests)
    must not leak into the next call or into child processes' environments."""
    global _debug_flag
    _debug_flag = on


def debug_enabled() -> bool:
    """``--debug`` on this command line, or ``ROBOCFG_DEBUG`` set (non-empty, not 0) by the user."""
    return _debug_flag or os.environ.get("ROBOCFG_DEBUG", "") not in ("", "0")


def console(stderr: bool = False):
    import sys

    from rich.console import Console

    stderr = stderr or _stdout_taken  # ``--json -`` owns standard output
    stream = sys.stderr if stderr else sys.stdout
    width = None if stream.isatty() else 160
    # emoji=False: rich would print "FILE:100:7" as "FILE💯7" (":100:" is an emoji code)
    return Console(stderr=stderr, highlight=False, soft_wrap=True, width=width, emoji=False)


def write_json(path: Path | None, payload: Any) -> None:
    """Write ``payload`` (a pydantic model, dataclass or plain data) as indented JSON.

    ``-`` writes to standard output. A file is written atomically: a temporary file in the same
    folder, flushed, then renamed over ``path``, so a reader (or a second writer, or a crash) never
    sees half a report and an older report is either kept whole or replaced whole.

    JSON has no NaN or infinity (``json.dumps`` would write the non-standard tokens ``NaN`` and
    ``Infinity``, which strict readers reject): a non-finite number, such as the pose of a body
    whose physics diverged, is written as ``null``."""
    import sys
    import tempfile

    if path is None:
        return
    if hasattr(payload, "model_dump"):
        payload = payload.model_dump(mode="json")
    text = json.dumps(_finite(payload), indent=2, sort_keys=False, default=_default, allow_nan=False) + "\n"
    if path == STDOUT:
        sys.stdout.write(text)
        sys.stdout.flush()
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _finite(o: Any) -> Any:
    """``o`` with every non-finite float in its dicts, lists and tuples replaced by None (the
    objects ``_default`` converts are converted first, so their floats are reached too)."""
    if isinstance(o, float):
        return o if o - o == 0.0 else None  # inf - inf and nan - nan are nan
    if isinstance(o, dict):
        return {k: _finite(v) for k, v in o.items()}
    if isinstance(o, list | tuple):
        return [_finite(v) for v in o]
    if isinstance(o, str | int | bool) or o is None:
        return o
    return _finite(_default(o))


def _default(o: Any) -> Any:
    import dataclasses

    if dataclasses.is_dataclass(o):
        return dataclasses.asdict(o)  # type: ignore[arg-type]
    if hasattr(o, "tolist"):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def load_task_for(task: str, kind: str, command: str, robot: str | None = None,
                  overrides: dict[str, Any] | None = None):
    """Find and check a task YAML by name or path; it must be a ``task: <kind>`` file.
    ``overrides``: fields changed by ``--set`` (see ``robocfg.cli.set_option``)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.errors import ConfigError

    checked = load_task(catalog.find("tasks", task), robot_override=robot, overrides=overrides)
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
