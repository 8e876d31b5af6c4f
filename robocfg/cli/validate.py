"""``robocfg validate``: check robot and task YAMLs (kind detected), directories recursively."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import JsonOpt, StrictOpt, console, write_json
from robocfg.cli.set_option import SetOpt, overrides


def validate(
    paths: Annotated[list[Path] | None, typer.Argument(
        help="YAML files, directories, or robot/task names; none = every robot and task on the search path.")] = None,
    strict: StrictOpt = False,
    json_path: JsonOpt = None,
    set_: SetOpt = None,
) -> None:
    """Check robot and task YAMLs against their schema and URDFs. Exit 0 valid, 2 invalid. With
    --set, each task file is checked with those fields changed (robot files as they are)."""
    from rich.table import Table

    from robocfg.cli.errors import format_problem
    from robocfg.config import catalog
    from robocfg.config.load import detect_kind, load_yaml
    from robocfg.errors import ConfigError, Problem

    changes = overrides(set_)
    files = _collect(paths) if paths else [*catalog.available("robots").values(), *catalog.available("tasks").values()]
    out, err = console(), console(stderr=True)
    table = Table(title="robocfg validate", show_lines=False)
    for col in ("file", "kind", "status", "errors", "warnings"):
        table.add_column(col)
    records, any_error = [], False
    for f in files:
        kind, problems, warnings = "?", [], []
        try:
            if f.is_dir():  # _collect keeps a folder only when it holds no YAML: nothing checked is no "ok"
                raise ConfigError([Problem(str(f), None, None, "", "no YAML files (*.yaml, *.yml) in this folder")])
            kind = detect_kind(load_yaml(f))
            # The checks (numpy, URDF parsing, the task models) are imported once a file has parsed:
            # a file refused by the size and nesting pre-scan is reported without them.
            from robocfg.checks import load_robot, load_task
            from robocfg.checks.task import CheckedTask

            checked = load_robot(f, strict) if kind == "robot" else load_task(f, strict, overrides=changes)
            warnings = checked.warnings
            if isinstance(checked, CheckedTask):  # the kind's checks needing kinematics, not simulation (IK reach)
                # asked of the kind's command face: a built-in kind's episode code stays unloaded
                from robocfg.engine.registry import command_for

                static = command_for(checked.config.task).static_problems(checked)
                if any(p.severity == "error" for p in static):
                    raise ConfigError(static)
                warnings = warnings + static
        except ConfigError as exc:
            problems = exc.problems
        errors = [p for p in problems if p.severity == "error"]
        warnings = warnings + [p for p in problems if p.severity == "warning"]
        failed = bool(problems)
        any_error |= failed
        status = "[red]invalid[/red]" if failed else ("[yellow]ok (warnings)[/yellow]" if warnings else "[green]ok[/green]")
        table.add_row(_short(f), kind, status, str(len(errors)), str(len(warnings)))
        for p in [*problems, *([w for w in warnings if w not in problems])]:
            err.print(format_problem(p), markup=False)
        records.append({"file": str(f), "kind": kind, "valid": not failed,
                        "problems": [p.__dict__ for p in problems], "warnings": [w.__dict__ for w in warnings]})
    out.print(table)
    write_json(json_path, {"valid": not any_error, "files": records})
    if any_error:
        raise typer.Exit(2)


def _collect(paths: list[Path]) -> list[Path]:
    files: list[Path] = []
    for p in paths:
        if p.is_dir():
            found = sorted(x for x in p.rglob("*") if x.suffix in (".yaml", ".yml") and x.is_file())
            files += found or [p]
        else:
            files.append(p if p.exists() else _by_name(p))
    return files


def _by_name(p: Path) -> Path:
    """A robot or task named on the search path (``pick_place``); else ``p`` (then reported missing)."""
    from robocfg.config import catalog

    if p.suffix or len(p.parts) != 1:
        return p
    found = {**catalog.available("tasks"), **catalog.available("robots")}  # robots win a shared name
    return found.get(str(p), found.get(str(p).replace("-", "_"), p))


def _short(p: Path) -> str:
    try:
        return str(p.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(p)
