"""Lever arms of an arm's joints about a frame's origin, at every configuration at once.

For a revolute joint ``j`` on the chain from the root to a frame, the frame origin ``p`` moves
with ``∂p/∂q_j = ω_j × (p − o_j)`` (``o_j`` on the joint's axis, ``ω_j`` its unit axis): its
length is at most ``|p − o_j|``. That distance changes with the joints below ``j``, but never
exceeds the sum of the fixed offsets along the chain from ``o_j`` to ``p`` (each joint's origin
is rigid in its parent joint's frame, the frame rigid in its joint's): ``lever[j]``, metres.
The same numbers bound the second derivatives: ``∂²p/∂q_i∂q_j = ω_a × (ω_b × (p − o_b))`` with
``b`` the one of ``i, j`` further down the chain (``a`` the other), so its length is at most
``lever[b] = min(lever[i], lever[j])`` (the sums shrink down the chain).

Joints off the chain do not move the frame: lever 0. A prismatic (or any non-revolute) joint on
the chain: no levers (``None``); callers then measure instead of bounding.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pinocchio as pin

_REVOLUTE = ("JointModelRX", "JointModelRY", "JointModelRZ", "JointModelRevoluteUnaligned")


def lever_arms(model: pin.Model, frame_id: int) -> tuple[float, ...] | None:
    """Per configuration coordinate (the model's q order), an upper bound (m) on the distance
    from that joint's axis to the origin of frame ``frame_id``, valid at every configuration;
    None when a joint on the frame's chain is not a 1-DoF revolute joint."""
    frame = model.frames[frame_id]
    levers = [0.0] * model.nq
    reach = _length(frame.placement.translation)  # |p − o_j| ≤ reach, starting at the frame's joint
    j = int(frame.parentJoint)
    while j > 0:
        joint = model.joints[j]
        if joint.shortname() not in _REVOLUTE or joint.nq != 1:
            return None
        levers[joint.idx_q] = reach
        reach += _length(model.jointPlacements[j].translation)  # o_j in its parent joint's frame
        j = int(model.parents[j])
    return tuple(levers)


def _length(v) -> float:
    x, y, z = (float(c) for c in v)
    return math.sqrt(x * x + y * y + z * z)
