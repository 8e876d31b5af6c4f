"""Task YAML schema: ``task:`` selects the command; the command's block holds its parameters.

Each kind's task model is :class:`~robocfg.config.task_base.TaskBase` with ``task: <kind>`` and the
kind's parameter block. ``pick_place``'s is made here; the other built-in kinds' are made in their
own modules (``gripper_task``, ``trajectory_task``, ``follow_target_task``, ``grasp_task``,
``multi_pick``) when :data:`TASK_MODELS` is first asked for them, so a process that validates and
runs one kind does not make every other kind's models (≈ 20 pydantic model classes). Their names
stay importable from here (``from robocfg.config.task import GripperTask``: made on that import).
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

import importlib
from collections.abc import Iterator, MutableMapping
from typing import TYPE_CHECKING, Annotated, Literal, cast

from pydantic import Field

from robocfg.config.commands import PickPlaceParams
from robocfg.config.task_base import (
    RobotMount as RobotMount,  # re-exported: the world imports it from here
)
from robocfg.config.task_base import TaskBase
from robocfg.config.types import Frozen

if TYPE_CHECKING:
    from typing_extensions import TypeForm  # PEP 747; typing has it from Python 3.14

    from robocfg.config.follow_target_task import FollowTargetTask
    from robocfg.config.grasp_task import GraspTask
    from robocfg.config.gripper_task import GripperTask
    from robocfg.config.multi_pick import PickPlaceManyTask
    from robocfg.config.trajectory_task import TrajectoryTask

class PickPlaceTask(TaskBase):
    task: Literal["pick_place"] = Field(description="The command this file configures; selects the parameter block.")
    pick_place: PickPlaceParams = Field(description="Parameters of `robocfg run pick-place`.")


# the built-in kinds in their order, each with the module and name of its task model
_BUILTIN: dict[str, tuple[str, str]] = {
    "gripper": ("robocfg.config.gripper_task", "GripperTask"),
    "trajectory": ("robocfg.config.trajectory_task", "TrajectoryTask"),
    "follow_target": ("robocfg.config.follow_target_task", "FollowTargetTask"),
    "pick_place": (__name__, "PickPlaceTask"),
    "grasp": ("robocfg.config.grasp_task", "GraspTask"),
    "pick_place_many": ("robocfg.config.multi_pick", "PickPlaceManyTask"),
}
_LAZY_NAMES = {name: module for module, name in _BUILTIN.values() if module != __name__}

if TYPE_CHECKING:
    TaskConfig = Annotated[
        GripperTask | TrajectoryTask | FollowTargetTask | PickPlaceTask | GraspTask | PickPlaceManyTask,
        Field(discriminator="task"),
    ]
    """The built-in task kinds as a static type (what type checkers see); the validator itself is
    built from ``TASK_MODELS`` by :func:`task_union`, so a kind registered later validates too.
    At run time the same ``Annotated`` union, made on first use (module ``__getattr__``)."""


def __getattr__(name: str) -> object:
    """The other built-in kinds' task models and ``TaskConfig``, made on first use."""
    if name in _LAZY_NAMES:
        return getattr(importlib.import_module(_LAZY_NAMES[name]), name)
    if name == "TaskConfig":
        members = tuple(TASK_MODELS[kind] for kind in _BUILTIN)
        config = Annotated[members[0] | members[1] | members[2] | members[3] | members[4] | members[5],  # type: ignore[valid-type]
                           Field(discriminator="task")]
        globals()["TaskConfig"] = config
        return config
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _TaskModels(MutableMapping[str, type[TaskBase]]):
    """Task kind → its task model, in declaration order; a built-in kind's model module is imported
    when the kind's model is first asked for (``[kind]``, ``get``, ``values``, ``items``), not when
    only its name is (``in``, iteration, ``len``)."""

    def __init__(self) -> None:
        self._models: dict[str, type[TaskBase] | None] = dict.fromkeys(_BUILTIN)
        self._models["pick_place"] = PickPlaceTask

    def __getitem__(self, kind: str) -> type[TaskBase]:
        model = self._models[kind]
        if model is None:
            module, name = _BUILTIN[kind]
            model = self._models[kind] = getattr(importlib.import_module(module), name)
        return model

    def __contains__(self, kind: object) -> bool:
        return kind in self._models

    def __setitem__(self, kind: str, model: type[TaskBase]) -> None:
        self._models[kind] = model

    def __delitem__(self, kind: str) -> None:
        del self._models[kind]

    def __iter__(self) -> Iterator[str]:
        return iter(self._models)

    def __len__(self) -> int:
        return len(self._models)


TASK_MODELS: MutableMapping[str, type[TaskBase]] = _TaskModels()
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


def remove_task_kind(kind: str) -> None:
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
