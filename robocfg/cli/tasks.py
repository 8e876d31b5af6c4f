"""``robocfg tasks``: the task YAMLs on the search path, with what each one runs."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from robocfg.cli.common import JsonOpt, console, write_json


@dataclass(frozen=True)
class TaskEntry:
    """One task file as listed: ``kind`` is its ``task:`` value (``pick_place``), ``command`` the
    command line that runs it, ``robots`` the robot names (or robot YAML paths) it mounts, first
    the one that runs the command. An invalid file is listed with its problem count."""

    name: str
    kind: str
    command: str
    robots: list[str]
    description: str
    source: str
    valid: bool
    problems: int = 0
    errors: list[str] = field(default_factory=list)


def tasks(json_path: JsonOpt = None) -> None:
    """List the tasks on the search path. Searched: ./tasks, $ROBOCFG_PATH, then the built-ins;
    each with its kind, robots, description and the command that runs it. The task file itself
    is checked (schema only; `robocfg validate` also loads its robots)."""
    from rich.table import Table

    from robocfg.config import catalog

    entries = [_entry(name, path) for name, path in catalog.available("tasks").items()]
    table = Table(title="tasks")
    for col in ("name", "kind", "robot", "description", "run with"):
        table.add_column(col)
    for e in entries:
        table.add_row(e.name, e.kind, ", ".join(e.robots),
                      e.description if e.valid else f"invalid ({e.problems} problems)", e.command)
    console().print(table)
    write_json(json_path, [asdict(e) for e in entries])


def _entry(name: str, path) -> TaskEntry:
    from robocfg.config.load import load_yaml
    from robocfg.config.task import TaskConfig
    from robocfg.config.validation import validate_document
    from robocfg.errors import ConfigError

    try:
        config = validate_document(load_yaml(path), TaskConfig)
    except ConfigError as exc:
        return TaskEntry(name, "?", "", [], "", str(path), False, len(exc.problems),
                         [p.format() for p in exc.problems])
    robots = [m.robot or str(m.robot_config_file) for m in config.robots]
    command = f"robocfg run {config.task.replace('_', '-')} {name}"
    return TaskEntry(name, config.task, command, robots, config.description, str(path), True)
