"""The ``gripper`` kind: its parameter block (``run gripper``) and task model. Made when a task of
this kind is first validated (``robocfg.config.task.TASK_MODELS``), not in every process."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field

from robocfg.config.task_base import TaskBase
from robocfg.config.types import (
    Frozen,
    NonNegFloat,
    PositiveFloat,
)


class GripperParams(Frozen):
    """``run gripper``: close then open, ``cycles`` times."""

    cycles: Annotated[int, Field(ge=1, le=100)] = 1
    mode: Literal["smooth", "direct"] = Field("smooth", description="smooth: rate-limited targets; direct: jump.")
    rate: PositiveFloat = Field(0.5, description="smooth mode: target change per second, as a fraction of the travel.")
    hold_time: PositiveFloat = Field(1.0, description="Time (s) allowed for each close or open.")
    hold_object: str | None = Field(None, description="Scene object placed between the fingers, to test holding.")
    lift_support_by: NonNegFloat = Field(0.0, description="Lower the object's support by this much (m) to test the hold.")


class GripperTask(TaskBase):
    task: Literal["gripper"] = Field(description="The command this file configures; selects the parameter block.")
    gripper: GripperParams = Field(default_factory=GripperParams, description="Parameters of `robocfg run gripper`.")
