"""Gripper behaviours registered by the YAML ``type:`` string (one registry, one mechanism)."""

from __future__ import annotations

import inspect
from typing import TYPE_CHECKING

from robocfg.errors import NotFound, RobocfgError

if TYPE_CHECKING:
    from robocfg.sim.gripper.base import Gripper
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World

GRIPPERS: dict[str, type[Gripper]] = {}


def register(type_name: str):
    """Class decorator: ``@register("parallel")``. A second class for the same name is an error, and
    so is a class that leaves an abstract method of :class:`Gripper` unimplemented."""

    def deco(cls: type[Gripper]) -> type[Gripper]:
        if type_name in GRIPPERS and GRIPPERS[type_name] is not cls:
            raise RobocfgError(f"gripper type {type_name!r} is already registered by {GRIPPERS[type_name].__name__}")
        if inspect.isabstract(cls):
            missing = ", ".join(sorted(getattr(cls, "__abstractmethods__", ())))
            raise RobocfgError(f"gripper class {cls.__name__} does not implement {missing}")
        GRIPPERS[type_name] = cls
        cls.type_name = type_name
        return cls

    return deco


def gripper_class(type_name: str) -> type[Gripper]:
    """The class for ``type_name``; NotFound lists the known types."""
    if type_name not in GRIPPERS:
        raise NotFound("gripper type", type_name, list(GRIPPERS))
    return GRIPPERS[type_name]


def make_gripper(world: World, arm: ArmHandle) -> Gripper | None:
    """Build the gripper of ``arm`` (an ArmHandle) in ``world``; None when the arm has none."""
    if arm.config.gripper is None:
        return None
    return gripper_class(arm.config.gripper.type)(world, arm)
