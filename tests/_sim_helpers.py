"""Shared helpers for the simulation tests: write a task YAML around a robot and load it."""

from __future__ import annotations

from pathlib import Path

import yaml

from robocfg.checks import load_task

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data"
SHIPPED_ROBOTS = sorted((ROOT / "robocfg" / "data" / "robots").glob("*.yaml"))
PANDA = ROOT / "robocfg" / "data" / "robots" / "panda.yaml"  # the reference robot of the generic tests


def make_task(tmp_path: Path, robot_file: Path | str, *, objects=(), mount=None, extra=None, task="gripper",
              name: str = "task.yaml"):
    """Write a minimal ``task: gripper`` YAML using ``robot_file`` (absolute path) and load it."""
    data = {
        "schema_version": 1,
        "task": task,
        "robots": [{"robot_config_file": str(Path(robot_file).resolve()), **(mount or {})}],
        "scene": {"ground": True, "objects": list(objects)},
    }
    for k, v in (extra or {}).items():
        data[k] = v
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)
