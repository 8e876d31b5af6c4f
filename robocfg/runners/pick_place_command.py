"""``run pick-place`` before anything runs: its help text and own options
(``robocfg run pick-place --help`` loads this module, not the episode code)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from robocfg.engine.dataset import DatasetOptions
from robocfg.engine.runner import TaskCommand

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.errors import Problem


@dataclass(frozen=True)
class PickPlaceOptions(DatasetOptions):
    """``run pick-place``'s own options: recording a dataset (the CLI builds the sink from them)."""


class PickPlaceCommand(TaskCommand):
    kind = "pick_place"
    Options = PickPlaceOptions
    verb = "placed"
    summary = ("Pick the task's object and place it, on any robot. Grasp → EE by R_ee_graspnet, ee_axis, "
               "tcp_offset.")
    description = (
        "Exit 0 when the success rate reaches --min-success (default: every episode), 1 otherwise; the "
        "--json report (one record per episode; no wall-clock figures, so the same seed gives the same "
        "file) is written either way. With --dataset every episode is recorded at --dataset-fps "
        "(observations, the joint-target + gripper actions that drove the robot, phase labels, images of "
        "the task's cameras) and the kept ones are written as a LeRobot v3.0 or robomimic HDF5 dataset; "
        "`robocfg dataset replay` re-simulates an episode from those actions.")
    episodic = True

    @classmethod
    def static_problems(cls, task: CheckedTask, arm: str | None = None) -> list[Problem]:
        """Poses out of the arm's reach (IK, tool down; nominal point or region corner), as warnings
        naming the phase that would fail: ``run`` then fails those episodes without simulating."""
        from robocfg.motion.placement import resolve_placement

        return [r.problem(task) for r in resolve_placement(task, arm).reach]
