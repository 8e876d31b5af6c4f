"""``run trajectory`` before anything runs: its help text and own options
(``robocfg run trajectory --help`` loads this module, not the episode code)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robocfg.engine.dataset import DatasetOptions
from robocfg.engine.options import option
from robocfg.engine.runner import TaskCommand


@dataclass(frozen=True)
class TrajectoryOptions(DatasetOptions):
    """``run trajectory``'s own options (and the ``--dataset*`` ones: the run is episode 0)."""

    plot: Path | None = field(default=None, metadata=option(
        "--plot", output=(".png",), help="Write a PNG of q, q̇, q̈ per joint against time (limits dashed)."))
    no_sim: bool = field(default=False, metadata=option("--no-sim", help="Plan and check only; do not simulate."))


class TrajectoryCommand(TaskCommand):
    kind = "trajectory"
    Options = TrajectoryOptions
    summary = ("Plan a time-optimal trajectory and track it. toppra; trapezoids "
               "with stop_at_waypoints; ruckig with a jerk limit; checked against the limits at 1 kHz, tracked "
               "in PyBullet. Prints duration, planning time, violations and tracking error.")
