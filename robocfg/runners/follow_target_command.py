"""``run follow-target`` before anything runs: its help text and own options
(``robocfg run follow-target --help`` loads this module, not the episode code)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robocfg.engine.dataset import DatasetOptions
from robocfg.engine.options import option
from robocfg.engine.runner import TaskCommand


@dataclass(frozen=True)
class FollowTargetOptions(DatasetOptions):
    """``run follow-target``'s own options (and the ``--dataset*`` ones: the run is episode 0)."""

    with_obstacle: bool | None = field(default=None, metadata=option(
        "--with-obstacle/--without-obstacle",
        help="Add the task's follow_target.obstacles (default: the task's with_obstacle)."))
    plot: Path | None = field(default=None, metadata=option(
        "--plot", output=(".png",), help="Save a plot (.png) of tracking error and clearance against time."))


class FollowTargetCommand(TaskCommand):
    kind = "follow_target"
    Options = FollowTargetOptions
    summary = ("Follow a moving target with the TCP, clear of obstacles. A static / waypoint / circle / figure-8 "
               "target tracked with a QP per control step (placo), keeping the safety margin from obstacles, "
               "table and ground. With --gui, drag the target with the sliders.")
    description = (
        "With --dataset the run is recorded as one episode at --dataset-fps: observations, the controller's "
        "commanded joint positions as actions (sent one frame ahead along its joint velocity, for the frame the "
        "recording's command gate delays them), success = the target was reached; `robocfg dataset replay` "
        "re-simulates it from those actions with the same target and obstacle motions.")
