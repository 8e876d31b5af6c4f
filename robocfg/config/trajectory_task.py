"""The ``trajectory`` kind: its parameter block (``run trajectory``) and task model. Made when a
task of this kind is first validated (``robocfg.config.task.TASK_MODELS``), not in every process.
Units: m, rad, s."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field

from robocfg.config.commands import Limits
from robocfg.config.task_base import TaskBase
from robocfg.config.types import (
    FiniteFloat,
    Frozen,
    NonNegFloat,
    Pose,
    PositiveFloat,
)

Waypoint = str | list[FiniteFloat] | dict[str, FiniteFloat] | Pose


def _home_only() -> list[Waypoint]:
    return ["home"]


class TrajectoryParams(Frozen):
    """``run trajectory``: time-optimal motion through joint-space or Cartesian waypoints."""

    waypoints: list[Waypoint] = Field(
        default_factory=_home_only,
        description="'home', a list in arm-joint order (rad), a {joint: rad} map, or a Cartesian TCP pose.",
    )
    stop_at_waypoints: bool = False
    limits: Limits = Field(default_factory=Limits)
    sample_rate: PositiveFloat = Field(240.0, description="Hz.")
    arm: str | None = Field(None, description="Arm that moves (default: the robot's first arm).")
    settle_time: NonNegFloat = Field(0.25, description="Time (s) the last waypoint is held after the trajectory ends.")
    gridpoints: Annotated[int, Field(ge=10, le=5000)] | None = Field(
        None, description="toppra grid size (default: 100, or 20 per segment for long paths)."
    )
    orientation_frame: Literal["tool", "ee_link"] = Field(
        "tool", description="Frame of the Cartesian waypoints' orientations. " "tool (default): orientations are the tool frame's (z = approach, y = fingers' closing axis, x = y × z, defined through the robot's R_ee_graspnet), so one orientation is one physical tool pose on every robot ([180, 0, 0]: tool pointing down). ee_link: the end-effector link's own frame, as written for one robot (the meaning before this option existed; the same for robots whose R_ee_graspnet is the Panda's).")
    placement: Literal["world", "auto"] = Field("world", description="world: Cartesian points are world coordinates (m), used as written. auto: world coordinates written for the robot the file names; a robot that cannot reach them (--robot) gets them moved with its arm: scaled about its arm base by the ratio of the two arms' reaches towards the points (see docs/task-yaml.md).")


class TrajectoryTask(TaskBase):
    task: Literal["trajectory"] = Field(description="The command this file configures; selects the parameter block.")
    trajectory: TrajectoryParams = Field(default_factory=TrajectoryParams, description="Parameters of `robocfg run trajectory`.")
