"""``run gripper`` before anything runs: its help text
(``robocfg run gripper --help`` loads this module, not the episode code)."""

from __future__ import annotations

from robocfg.engine.runner import TaskCommand


class GripperCommand(TaskCommand):
    kind = "gripper"
    summary = ("Close and open the gripper, then hold a cube. Reports measured widths, timing, mimic error and "
               "the hold test.")
