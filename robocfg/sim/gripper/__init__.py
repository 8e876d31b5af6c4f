"""Gripper behaviours keyed by the robot YAML's ``gripper.type`` (``parallel``, ``suction``)."""

from robocfg.sim.gripper import parallel, suction  # noqa: F401  (registers the built-in types)
from robocfg.sim.gripper.base import CLOSED, OPEN, Gripper
from robocfg.sim.gripper.parallel import ParallelGripper
from robocfg.sim.gripper.registry import GRIPPERS, gripper_class, make_gripper, register
from robocfg.sim.gripper.suction import SuctionGripper

__all__ = ["CLOSED", "GRIPPERS", "OPEN", "Gripper", "ParallelGripper", "SuctionGripper",
           "gripper_class", "make_gripper", "register"]
