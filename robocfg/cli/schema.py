"""``robocfg schema robot|task``: JSON Schema for editors."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Literal

import typer


def schema(
    kind: Annotated[str, typer.Argument(help="robot or task")],
    output: Annotated[Path | None, typer.Option("-o", "--output", help="Write to this file instead of stdout.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing output file.")] = False,
) -> None:
    """Print the JSON Schema of robot or task YAMLs (for yaml-language-server)."""
    from robocfg.errors import NotFound

    if kind not in ("robot", "task"):
        raise NotFound("schema kind", kind, ["robot", "task"])
    text = json.dumps(json_schema(kind), indent=2) + "\n"  # type: ignore[arg-type]
    if output is None:
        typer.echo(text, nl=False)
        return
    if output.exists() and not force and output.read_text() != text:
        from robocfg.errors import RobocfgError

        raise RobocfgError(f"{output} exists; use --force to overwrite it")
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(text)


def json_schema(kind: Literal["robot", "task"]) -> dict:
    from pydantic import TypeAdapter

    if kind == "robot":
        from robocfg.config.robot import RobotConfig

        out = RobotConfig.model_json_schema()
    else:
        from robocfg.config.task import TaskConfig

        out = TypeAdapter(TaskConfig).model_json_schema()
    out["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    out["title"] = f"robocfg {kind} YAML (schema_version 1)"
    return out
