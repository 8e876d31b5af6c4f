"""Task YAML schema: ``task:`` selects the command; the command's block holds its parameters."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import TYPE_CHECKING, Annotated, Literal, cast

from pydantic import Field, JsonValue, model_validator

from robocfg.config.cameras import TaskCamera
from robocfg.config.commands import (
    FollowTargetParams,
    GraspParams,
    GripperParams,
    PickPlaceParams,
    TrajectoryParams,
)
from robocfg.config.multi_pick import PickPlaceManyParams
from robocfg.config.scene import Scene, Sim
from robocfg.config.types import Frozen, Pose, SchemaVersion, new_list

if TYPE_CHECKING:
    from typing_extensions import TypeForm  # PEP 747; typing has it from Python 3.14


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


class GripperTask(TaskBase):
    task: Literal["gripper"] = Field(description="The command this file configures; selects the parameter block.")
    gripper: GripperParams = Field(default_factory=GripperParams, description="Parameters of `robocfg run gripper`.")


class TrajectoryTask(TaskBase):
    task: Literal["trajectory"] = Field(description="The command this file configures; selects the parameter block.")
    trajectory: TrajectoryParams = Field(default_factory=TrajectoryParams, description="Parameters of `robocfg run trajectory`.")


class FollowTargetTask(TaskBase):
    task: Literal["follow_target"] = Field(description="The command this file configures; selects the parameter block.")
    follow_target: FollowTargetParams = Field(default_factory=FollowTargetParams, description="Parameters of `robocfg run follow-target`.")


class PickPlaceTask(TaskBase):
    task: Literal["pick_place"] = Field(description="The command this file configures; selects the parameter block.")
    pick_place: PickPlaceParams = Field(description="Parameters of `robocfg run pick-place`.")


class PickPlaceManyTask(TaskBase):
    task: Literal["pick_place_many"] = Field(description="The command this file configures; selects the parameter block.")
    pick_place_many: PickPlaceManyParams = Field(description="Parameters of `robocfg run pick-place-many`.")


class GraspTask(TaskBase):
    task: Literal["grasp"] = Field(description="The command this file configures; selects the parameter block.")
    grasp: GraspParams = Field(default_factory=GraspParams, description="Parameters of `robocfg run grasp`.")


TaskConfig = Annotated[
    GripperTask | TrajectoryTask | FollowTargetTask | PickPlaceTask | GraspTask | PickPlaceManyTask,
    Field(discriminator="task"),
]
"""The built-in task kinds as a static type (what type checkers see); the validator itself is
built from ``TASK_MODELS`` by :func:`task_union`, so a kind registered later validates too."""

TASK_MODELS: dict[str, type[TaskBase]] = {
    "gripper": GripperTask, "trajectory": TrajectoryTask, "follow_target": FollowTargetTask,
    "pick_place": PickPlaceTask, "grasp": GraspTask, "pick_place_many": PickPlaceManyTask,
}
"""Task kind (the YAML's ``task:`` value) → its task model. The runner registry
(``robocfg.engine.registry``) pairs each kind with its runner; a test checks the two agree.
Every model holds the kind's parameters under a key named like the kind."""

TASK_KINDS = tuple(TASK_MODELS)
_BUILTIN_KINDS = frozenset(TASK_MODELS)


def params_model(kind: str) -> type[Frozen]:
    """The parameter model of ``kind`` (the type of the task model's ``<kind>`` field)."""
    annotation = TASK_MODELS[kind].model_fields[kind].annotation
    assert isinstance(annotation, type)  # every task model declares its block as one model class
    return annotation


def add_task_kind(kind: str, params: type[Frozen], description: str = "") -> type[TaskBase]:
    """Declare a new task kind: a task model with ``task: <kind>`` and a ``<kind>:`` block of
    ``params`` (defaults used when the block is left out) is added to ``TASK_MODELS``.
    Declaring the same kind again with the same ``params`` returns the existing model; with other
    ``params`` it is an error (two kinds cannot share a name)."""
    from pydantic import create_model

    if kind in TASK_MODELS:
        if params_model(kind) is not params:
            raise ValueError(f"task kind {kind!r} is already declared with {params_model(kind).__name__}")
        return TASK_MODELS[kind]
    if not kind.isidentifier():
        raise ValueError(f"task kind {kind!r} must be a Python identifier (it is also the YAML key of its block)")
    name = "".join(w.capitalize() for w in kind.split("_")) + "Task"
    fields: dict = {
        "task": (Literal[kind], Field(description="The command this file configures; selects the parameter block.")),
        kind: (params, Field(default_factory=params, description=description or f"Parameters of `robocfg run {kind}`.")),
    }
    model = create_model(name, __base__=TaskBase, **fields)
    TASK_MODELS[kind] = model
    return model


def remove_task_kind(kind: str) -> "None":
    """Forget a kind declared with :func:`add_task_kind` (the built-in ones stay)."""
    if kind in _BUILTIN_KINDS:
        raise ValueError(f"task kind {kind!r} is built in")
    TASK_MODELS.pop(kind, None)


def task_union() -> "TypeForm[TaskBase]":
    """The discriminated union of every declared task kind (what a task YAML validates against)."""
    from functools import reduce
    from operator import or_

    # Built at run time from the kinds declared so far, so no static type expression spells it;
    # every member is a TaskBase subclass, which is what the cast states.
    return cast("TypeForm[TaskBase]", Annotated[reduce(or_, TASK_MODELS.values()), Field(discriminator="task")])
