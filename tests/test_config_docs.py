"""docs/robot-yaml.md and docs/task-yaml.md stay in step with the models and the Panda file."""

from __future__ import annotations

import re
import typing
from pathlib import Path

import pytest

from robocfg.cli.schema import markdown_text
from robocfg.cli.schema_markdown import END, _collect
from robocfg.config.robot import RobotConfig
from robocfg.config.task import TaskConfig

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"


@pytest.mark.parametrize("kind", ["robot", "task"])
def test_generated_field_tables_are_current(kind):
    """Refresh with `robocfg schema KIND --markdown -o docs/KIND-yaml.md` after changing a model."""
    doc = (DOCS / f"{kind}-yaml.md").read_text()
    block = markdown_text(kind)
    start = doc.index(block.splitlines()[0])
    assert doc[start:doc.index(END) + len(END)] + "\n" == block, f"docs/{kind}-yaml.md field tables are stale"


@pytest.mark.parametrize(("kind", "roots"), [
    ("robot", [RobotConfig]),
    ("task", list(typing.get_args(typing.get_args(TaskConfig)[0]))),
])
def test_every_field_is_documented(kind, roots):
    doc = (DOCS / f"{kind}-yaml.md").read_text()
    for cls in _collect(roots):
        assert f"### `{cls.__name__}`" in doc
        section = doc.split(f"### `{cls.__name__}`", 1)[1].split("\n### ", 1)[0]
        for name in cls.model_fields:
            assert f"| `{name}` |" in section, f"{cls.__name__}.{name}"


def test_worked_example_is_the_shipped_panda():
    doc = (DOCS / "robot-yaml.md").read_text()
    [example] = [b for b in re.findall(r"```yaml\n(.*?)```", doc, re.S) if "name: panda" in b]
    assert example == (ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text()


def test_docs_state_the_conventions():
    robot = (DOCS / "robot-yaml.md").read_text()
    for phrase in ("world_R_ee = world_R_grasp · R_ee_graspnet", "x = approach direction", "y = closing direction",
                   "z = x × y", "DOF indices", "pybullet_data://", "airo_models://", "package://", "$ROBOCFG_PATH",
                   "--strict", "warning", "tcp_offset"):
        assert phrase in robot, phrase
    task = (DOCS / "task-yaml.md").read_text()
    for phrase in ("quat_xyzw", "quat_wxyz", "euler_deg", "Rz(yaw) · Ry(pitch) · Rx(roll)", "robot_config_file", "--strict"):
        assert phrase in task, phrase
