"""What every task YAML has, whatever its kind: the robots and where they stand, the scene, the
simulation settings, the dataset cameras, the per-robot variants. Each kind's task model
(``robocfg.config.task.TASK_MODELS``) adds ``task: <kind>`` and the kind's parameter block."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from pydantic import Field, JsonValue, model_validator

from robocfg.config.cameras import TaskCamera
from robocfg.config.scene import Scene, Sim
from robocfg.config.types import Frozen, Pose, SchemaVersion, new_list


class RobotMount(Pose):
    """Which robot, and where its base stands (world frame)."""

    robot: str | None = Field(None, description="Robot name on the search path (e.g. 'panda').")
    robot_config_file: str | None = Field(None, description="Path to a robot YAML, relative to this task file.")
    ignore_substring: list[str] = Field(default_factory=new_list, description="Bodies whose name contains one of these do not collide with the robot.")

    @model_validator(mode="after")
    def _one_source(self) -> "RobotMount":
        if (self.robot is None) == (self.robot_config_file is None):
            raise ValueError("give exactly one of 'robot' (a name) or 'robot_config_file' (a path)")
        return self


class TaskBase(Frozen):
    """Fields every task YAML has, whatever its kind."""

    schema_version: SchemaVersion = Field(description="File format version; this is 1.")
    description: str = Field("", description="Free text.")
    robots: list[RobotMount] = Field(min_length=1, description="Robots in the scene; the first one runs the command.")
    scene: Scene = Field(default_factory=Scene, description="Everything in the world besides the robots.")
    sim: Sim = Field(default_factory=Sim, description="Simulation settings.")
    cameras: list[TaskCamera] = Field(default_factory=new_list, description="Cameras recorded into datasets (--dataset); none: state only.")
    variants: dict[str, dict[str, JsonValue]] = Field(
        default_factory=dict,
        description="Per-robot changes: robot name → {dotted key: value} (as `--set`), applied when that robot "
                    "runs the task (first in `robots`, or chosen with `--robot`). For cells whose robots differ in "
                    "reach: each robot gets fixtures and pick/place points it can reach.",
    )
