"""``run grasp`` before anything runs: its help text and own options
(``robocfg run grasp --help`` loads this module, not the episode code)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robocfg.engine.dataset import DatasetOptions
from robocfg.engine.options import option
from robocfg.engine.runner import TaskCommand


@dataclass(frozen=True)
class GraspOptions(DatasetOptions):
    """``run grasp``'s own options (and the ``--dataset*`` ones)."""

    save_cloud: Path | None = field(default=None, metadata=option(
        "--save-cloud", output=(".npz", ".ply"), help="Write the first object cloud (.npz or .ply)."))


class GraspCommand(TaskCommand):
    kind = "grasp"
    Options = GraspOptions
    verb = "lifted"
    summary = ("Grasp objects, planning from simulated depth cameras. Perceive the object with RGB-D "
               "cameras, plan antipodal grasps on the point cloud, execute the best, lift, shake and verify; "
               "retry the next-ranked grasp on failure.")
    description = (
        "Grasp → EE by R_ee_graspnet, ee_axis, tcp_offset. Episode k grasps objects[k % n]. Exit 0 when the "
        "lift success rate reaches --min-success, 1 otherwise (no object points in the workspace, no feasible "
        "grasp, or the object was not held). --record draws the candidate grasps.")
    episodic = True
