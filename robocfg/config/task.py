"""Task YAML schema: ``task:`` selects the command; the command's block holds its parameters."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.cameras import TaskCamera
from robocfg.config.commands import (
    FollowTargetParams,
    GraspParams,
    GripperParams,
    PickPlaceParams,
    TrajectoryParams,
)
from robocfg.config.scene import Scene, Sim
from robocfg.config.types import Frozen, Pose, SchemaVersion


class RobotMount(Pose):
    """Which robot, and where its base stands (world frame)."""

    robot: str | None = Field(None, description="Robot name on the search path (e.g. 'panda').")
    robot_config_file: str | None = Field(None, description="Path to a robot YAML, relative to this task file.")
    ignore_substring: list[str] = Field(default_factory=list, description="Bodies whose name contains one of these do not collide with the robot.")

    @model_validator(mode="after")
    def _one_source(self) -> RobotMount:
        if (self.robot is None) == (self.robot_config_file is None):
            raise ValueError("give exactly one of 'robot' (a name) or 'robot_config_file' (a path)")
        return self


class _TaskBase(Frozen):
    schema_version: SchemaVersion = Field(description="File format version; this is 1.")
    description: str = Field("", description="Free text.")
    robots: list[RobotMount] = Field(min_length=1, description="Robots in the scene; the first one runs the command.")
    scene: Scene = Field(default_factory=Scene, description="Everything in the world besides the robots.")
    sim: Sim = Field(default_factory=Sim, description="Simulation settings.")
    cameras: list[TaskCamera] = Field(default_factory=list, description="Cameras recorded into datasets (--dataset); none: state only.")


class GripperTask(_TaskBase):
    task: Literal["gripper"] = Field(description="The command this file configures; selects the parameter block.")
    gripper: GripperParams = Field(default_factory=GripperParams, description="Parameters of `robocfg run gripper`.")


class TrajectoryTask(_TaskBase):
    task: Literal["trajectory"] = Field(description="The command this file configures; selects the parameter block.")
    trajectory: TrajectoryParams = Field(default_factory=TrajectoryParams, description="Parameters of `robocfg run trajectory`.")


class FollowTargetTask(_TaskBase):
    task: Literal["follow_target"] = Field(description="The command this file configures; selects the parameter block.")
    follow_target: FollowTargetParams = Field(default_factory=FollowTargetParams, description="Parameters of `robocfg run follow-target`.")


class PickPlaceTask(_TaskBase):
    task: Literal["pick_place"] = Field(description="The command this file configures; selects the parameter block.")
    pick_place: PickPlaceParams = Field(description="Parameters of `robocfg run pick-place`.")


class GraspTask(_TaskBase):
    task: Literal["grasp"] = Field(description="The command this file configures; selects the parameter block.")
    grasp: GraspParams = Field(default_factory=GraspParams, description="Parameters of `robocfg run grasp`.")


TaskConfig = Annotated[
    GripperTask | TrajectoryTask | FollowTargetTask | PickPlaceTask | GraspTask,
    Field(discriminator="task"),
]
TASK_KINDS = ("gripper", "trajectory", "follow_target", "pick_place", "grasp")
