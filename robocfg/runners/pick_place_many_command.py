"""``run pick-place-many`` before anything runs: its help text and own options
(``robocfg run pick-place-many --help`` loads this module, not the episode code)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from robocfg.engine.dataset import DatasetOptions
from robocfg.engine.runner import TaskCommand

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.errors import Problem


@dataclass(frozen=True)
class PickPlaceManyOptions(DatasetOptions):
    """``run pick-place-many``'s own options: recording a dataset (the CLI builds the sink)."""


class PickPlaceManyCommand(TaskCommand):
    kind = "pick_place_many"
    Options = PickPlaceManyOptions
    verb = "cleared"
    summary = "Pick objects in turn into a bin or onto a shelf."
    description = (
        "Each episode randomises every object in its own region, then picks them one at a time (listed order, or "
        "by reachability) with grasps filtered for collisions of the whole arm and gripper with the neighbours and "
        "fixtures, and places them on spots spaced so they do not land on each other. Exit 0 when the share of "
        "episodes with every object placed reaches --min-success; failures name the object and the phase. With "
        "--dataset every episode is recorded as for pick-place, the environment state holding every object's pose "
        "in the task's order; `robocfg dataset replay` re-simulates an episode from its actions.")
    episodic = True

    @classmethod
    def static_problems(cls, task: CheckedTask, arm: str | None = None) -> list[Problem]:
        """Every object's and place spot's poses out of the arm's reach
        (:func:`robocfg.runners.pick_place_many.reach_many`): a nominal pose is an error, a region
        corner a warning."""
        from robocfg.runners.pick_place_many import reach_many

        return reach_many(task, arm)
