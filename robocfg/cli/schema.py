"""``robocfg schema robot|task``: JSON Schema for editors."""

from __future__ import annotations

import json
import typing
from pathlib import Path
from typing import Annotated, Literal

import typer


def schema(
    kind: Annotated[str, typer.Argument(help="robot, task, or a run report: report-KIND (report-pick-place, "
                                             "report-grasp, report-gripper, report-trajectory, report-follow-target)")],
    output: Annotated[Path | None, typer.Option("-o", "--output", help="Write to this file instead of stdout.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing output file.")] = False,
    markdown: Annotated[bool, typer.Option("--markdown", help="Field reference tables (Markdown) instead of JSON Schema; "
                                           "with -o, replaces only the generated block of an existing document.")] = False,
) -> None:
    """Print the JSON Schema of robot or task YAMLs, or of a run report. The YAML schemas are what
    yaml-language-server reads to check files in an editor; a report schema describes --json."""
    from robocfg.errors import NotFound

    reports = report_kinds()
    if kind not in ("robot", "task", *reports):
        raise NotFound("schema kind", kind, ["robot", "task", *reports])
    if kind in reports:
        text = json.dumps(report_schema(kind), indent=2) + "\n"
    elif markdown:
        text = markdown_text(kind)  # type: ignore[arg-type]
        if output is not None and output.exists():
            from robocfg.cli.schema_markdown import replace_block

            merged = replace_block(output.read_text(), text)
            if merged is not None:
                output.write_text(merged)
                return
    else:
        text = json.dumps(json_schema(kind), indent=2) + "\n"  # type: ignore[arg-type]
    if output is None:
        typer.echo(text, nl=False)
        return
    if output.exists() and not force and output.read_text() != text:
        from robocfg.errors import RobocfgError

        raise RobocfgError(f"{output} exists; use --force to overwrite it")
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(text)


def report_kinds() -> list[str]:
    """``report-<command>`` of every registered task kind."""
    from robocfg.engine.registry import command_name, registered

    return [f"report-{command_name(k)}" for k in registered()]


def report_schema(kind: str) -> dict:
    """JSON Schema of a ``run`` command's ``--json`` report, from its typed report dataclass."""
    from pydantic import TypeAdapter

    from robocfg.engine.registry import command_name, registered
    from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION

    report = next(r.report for k, r in registered().items() if f"report-{command_name(k)}" == kind)
    out = TypeAdapter(report).json_schema(mode="serialization")
    out["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    out["title"] = f"robocfg run {kind.removeprefix('report-')} --json report (schema_version {REPORT_SCHEMA_VERSION})"
    return out


def json_schema(kind: Literal["robot", "task"]) -> dict:
    from pydantic import TypeAdapter

    if kind == "robot":
        from robocfg.config.robot import RobotConfig

        out = RobotConfig.model_json_schema()
    else:
        from robocfg.config.task import TaskConfig

        out = TypeAdapter(TaskConfig).json_schema()
    out["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    out["title"] = f"robocfg {kind} YAML (schema_version 1)"
    return out


def markdown_text(kind: Literal["robot", "task"]) -> str:
    """Field tables for docs/KIND-yaml.md, from the models."""
    from robocfg.cli.schema_markdown import markdown_reference

    if kind == "robot":
        from robocfg.config.robot import RobotConfig

        roots: list = [RobotConfig]
    else:
        from robocfg.config.task import TaskConfig

        roots = list(typing.get_args(typing.get_args(TaskConfig)[0]))  # the union's members
    return markdown_reference(kind, json_schema(kind), roots)
