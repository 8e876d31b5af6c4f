"""One-jaw gripper: one driven jaw closing against a jaw fixed to the hand (Unitree Z1 style).

It drives and reports like a parallel gripper — the driven joint in position control,
``is_grasping`` when both jaws touch the body — so it reuses that class. Two things differ:

* **width** is the gap between the jaws' *pads* (the distal part of each jaw's collision
  geometry, as ``robocfg validate`` measures it) along the closing direction, at the link poses
  the simulator reports now. The closest distance between the two whole collision shapes, as a
  parallel gripper uses, stays near zero on a revolute jaw: its hull and the fixed jaw's meet at
  the pivot whatever the opening;
* where the object ends up: against the fixed jaw, mid-way between the jaw faces at the grasp
  width (``fixed_jaw_face − width/2`` across the ee_axis line; ``robocfg.kinematics.frames``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robocfg.assets.fingers import FingerGeometryMissing, closing_axis, finger_points, pad_points
from robocfg.assets.paths import Resolver
from robocfg.config.robot import OneJawGripperConfig
from robocfg.config.types import AXIS_INDEX
from robocfg.sim.gripper.parallel import ParallelGripper
from robocfg.sim.gripper.registry import register

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World


@register("one_jaw")
class OneJawGripper(ParallelGripper):
    """``finger_links[0]`` is the moving jaw, ``finger_links[1]`` the fixed one."""

    config: OneJawGripperConfig

    def __init__(self, world: World, arm: ArmHandle, rate: float | None = None):
        super().__init__(world, arm, rate)
        self._pads = _pads_in_link_frames(arm)

    @property
    def moving_jaw(self) -> int:
        """PyBullet link index of the moving jaw."""
        return self.fingers[0]

    @property
    def fixed_jaw(self) -> int:
        """PyBullet link index of the fixed jaw."""
        return self.fingers[1]

    def width(self) -> float:
        """Measured gap (m, ≥ 0) between the moving jaw's pad and the fixed jaw's pad along the
        closing direction, at the current link poses; the parallel measure without pad geometry."""
        if self._pads is None:
            return super().width()
        r, cfg = self.robot, self.config
        c = self.arm.ee_pose()[:3, :3] @ closing_axis(self.arm.config.R_ee_graspnet)
        proj = []
        for link, P in zip(cfg.finger_links, self._pads, strict=True):
            T = r.link_pose(link)
            proj.append((P @ T[:3, :3].T + T[:3, 3]) @ c)
        return max(0.0, float(proj[1].min() - proj[0].max()))


def _pads_in_link_frames(arm: ArmHandle) -> list[np.ndarray] | None:
    """Pad points of [moving jaw, fixed jaw], each in its own link frame (pads measured at the
    closed position, where the moving jaw's distal part faces the fixed jaw), or None."""
    checked, cfg = arm.robot.checked, arm.config
    g = cfg.gripper
    if not isinstance(g, OneJawGripperConfig):
        return None
    urdf, links = checked.urdf, list(g.finger_links)
    q = dict(zip(checked.gripper_joints(cfg), g.closed, strict=True))
    try:
        pads = pad_points(urdf, cfg.ee_link, links, finger_points(urdf, Resolver(checked.path.parent, checked.config.package_dirs), links),
                          q, AXIS_INDEX[cfg.ee_axis])
    except FingerGeometryMissing:
        return None
    T_ee = urdf.link_pose(cfg.ee_link, q)
    out = []
    for link, P in zip(links, pads, strict=True):
        T = np.linalg.inv(urdf.link_pose(link, q)) @ T_ee  # ee frame → link frame
        out.append(P @ T[:3, :3].T + T[:3, 3])
    return out
