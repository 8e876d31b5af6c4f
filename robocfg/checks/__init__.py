"""Cross-checks of robot and task YAMLs against their URDFs (no simulator needed)."""

from robocfg.checks.robot import CheckedRobot, load_robot
from robocfg.checks.task import CheckedTask, load_task

__all__ = ["CheckedRobot", "CheckedTask", "load_robot", "load_task"]
