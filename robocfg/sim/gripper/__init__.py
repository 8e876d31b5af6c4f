"""Gripper behaviours keyed by the robot YAML's ``gripper.type`` (``parallel``, ``one_jaw``, ``suction``)."""

from robocfg.sim.gripper import one_jaw, parallel, suction  # noqa: F401  (registers the built-in types)
from robocfg.sim.gripper.base import CLOSED, OPEN, Gripper
from robocfg.sim.gripper.one_jaw import OneJawGripper
from robocfg.sim.gripper.parallel import ParallelGripper
from robocfg.sim.gripper.registry import GRIPPERS, gripper_class, make_gripper, register
from robocfg.sim.gripper.suction import SuctionGripper

__all__ = ["CLOSED", "GRIPPERS", "OPEN", "Gripper", "OneJawGripper", "ParallelGripper", "SuctionGripper",
           "gripper_class", "make_gripper", "register"]
