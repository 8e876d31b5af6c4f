"""One-jaw gripper: one driven jaw closing against a jaw fixed to the hand (Unitree Z1 style).

It drives, measures and reports like a parallel gripper — the driven joint in position control,
the width *measured* as the closest distance between the moving and the fixed jaw's collision
shapes, ``is_grasping`` when both jaws touch the body — so it reuses that class. What differs is
where the object ends up: against the fixed jaw, mid-way between the jaw faces at the grasp width
(``fixed_jaw_face − width/2`` across the ee_axis line; see ``robocfg.kinematics.frames``), which
the grasp → EE conversion accounts for.
"""

from __future__ import annotations

from robocfg.config.robot import OneJawGripperConfig
from robocfg.sim.gripper.parallel import ParallelGripper
from robocfg.sim.gripper.registry import register


@register("one_jaw")
class OneJawGripper(ParallelGripper):
    """``finger_links[0]`` is the moving jaw, ``finger_links[1]`` the fixed one."""

    config: OneJawGripperConfig

    @property
    def moving_jaw(self) -> int:
        """PyBullet link index of the moving jaw."""
        return self.fingers[0]

    @property
    def fixed_jaw(self) -> int:
        """PyBullet link index of the fixed jaw."""
        return self.fingers[1]
