"""A necessary condition for an arm pose, answered without IK: how far the arm's chain can stretch.

For an arm of revolute joints, the distance between the origins of two consecutive joints is
fixed (the next joint's origin is rigid in the previous joint's child link), so the last arm
joint's origin is never further from the first's than the sum of those distances, ``length``.
A target pose of ``ee_link`` fixes where the last joint's origin would be (it is rigid in the
ee_link frame too): when that point lies further than ``length`` from the first joint's origin
(which no arm joint moves), no joint values reach the pose, and IK — which would spend its whole
iteration budget failing — need not be asked. Where the bound says "maybe", IK answers as before,
so a search that skips the impossible poses gives the same answer.

Frames: world; metres. Prismatic arm joints change the distances: the bound is not used then
(``may_reach`` always True).
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robocfg.kinematics.model import KinematicModel

SLACK = 1e-3  # m added to the bound: more than any IK position tolerance


@dataclass(frozen=True)
class ChainBound:
    """``|o_last(T_ee) − origin| ≤ length`` for every reachable ee_link pose ``T_ee``."""

    origin: np.ndarray | None  # world position of the first arm joint's origin (m); None: no bound
    length: float  # m, sum of the distances between consecutive arm joint origins
    last_in_ee: np.ndarray  # the last arm joint's origin in the ee_link frame (m)

    @classmethod
    def of(cls, model: KinematicModel) -> ChainBound:
        """The bound of ``model``'s arm (its ee_link frame ``"ee"``), measured at the home pose."""
        import pinocchio as pin

        m, data = model.model, model.model.createData()
        revolute = all(m.joints[j].shortname().startswith(("JointModelR", "JointModelRevolute"))
                       for j in range(1, m.njoints))
        q = model._q(np.asarray(model.home, float))
        pin.forwardKinematics(m, data, q)
        pin.updateFramePlacements(m, data)
        origins = [np.array(data.oMi[j].translation) for j in range(1, m.njoints)]
        T_ee = data.oMf[model.frame_id("ee")].homogeneous
        last_in_ee = T_ee[:3, :3].T @ (origins[-1] - T_ee[:3, 3])
        if not revolute or not origins:
            return cls(None, 0.0, last_in_ee)
        length = float(sum(np.linalg.norm(b - a) for a, b in pairwise(origins)))
        return cls(origins[0], length, last_in_ee)

    def may_reach(self, T_ee: np.ndarray) -> bool:
        """False only when no joint values can put ee_link at ``T_ee`` (4x4, world)."""
        if self.origin is None:
            return True
        last = T_ee[:3, 3] + T_ee[:3, :3] @ self.last_in_ee
        return float(np.linalg.norm(last - self.origin)) <= self.length + SLACK
