"""What ``robocfg view`` shows: a robot YAML or a task YAML, found by path or by name.

A name is looked up among the robots first, then the tasks (the search path of
:mod:`robocfg.config.catalog`); a path's kind comes from its top-level keys.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from robocfg.checks import CheckedRobot, CheckedTask, load_robot, load_task
from robocfg.config import catalog
from robocfg.config.load import detect_kind, load_yaml
from robocfg.config.overrides import OVERRIDE_SOURCE
from robocfg.errors import ConfigError, NotFound, Problem


@dataclass(frozen=True)
class ViewSource:
    """A robot or task YAML file to show."""

    kind: Literal["robot", "task"]
    path: Path
    overrides: Mapping[str, Any] = field(default_factory=dict)  # a task's changed fields (``--set``)

    def load(self) -> CheckedRobot | CheckedTask:
        """Load and check the file (ConfigError with FILE:LINE problems if it is invalid)."""
        return load_robot(self.path) if self.kind == "robot" else load_task(self.path, overrides=self.overrides)

    def robots(self, checked: CheckedRobot | CheckedTask) -> list[CheckedRobot]:
        return [checked] if isinstance(checked, CheckedRobot) else list(checked.robots)


def find_source(name_or_path: str, overrides: Mapping[str, Any] | None = None) -> ViewSource:
    """The robot or task YAML meant by ``name_or_path``; ``overrides`` change a task's fields."""
    source = _find(name_or_path)
    if overrides:
        if source.kind != "task":
            raise ConfigError([Problem(OVERRIDE_SOURCE, None, None, "",
                                       f"{name_or_path!r} is a robot; overrides change the fields of a task")])
        return ViewSource("task", source.path, dict(overrides))
    return source


def _find(name_or_path: str) -> ViewSource:
    path = Path(name_or_path).expanduser()
    if path.is_file():
        kind = detect_kind(load_yaml(path))
        return ViewSource("robot" if kind == "robot" else "task", path)
    robots, tasks = catalog.available("robots"), catalog.available("tasks")
    kinds: tuple[tuple[Literal["robot", "task"], dict[str, Path]], ...] = (("robot", robots), ("task", tasks))
    for kind, found in kinds:
        for name in (name_or_path, name_or_path.replace("-", "_"), Path(name_or_path).stem):
            if name in found:
                return ViewSource(kind, found[name])
    raise NotFound("robot or task", name_or_path, [*robots, *tasks])
