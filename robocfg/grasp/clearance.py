"""Does the gripper fit at a grasp: its boxes (:class:`~robocfg.grasp.gripper_model.GripperBoxes`,
in the GraspNet grasp frame: x approach, y closing) against a scene cloud and a horizontal support
plane, for many grasp poses at once (world frame, m). Used by the antipodal planner's filters.
"""

from __future__ import annotations

import numpy as np

from robocfg.grasp.gripper_model import CLOSING_TOLERANCE, GripperBoxes
from robocfg.kinematics.frames import Grasp

LINKAGE_MARGIN = 0.001  # m: clearance kept between closing knuckles/linkages and the cloud


def above_support(centers, rots, boxes: GripperBoxes, support_z: float) -> np.ndarray:
    """True where every corner of every box stays above the support plane z = ``support_z``."""
    lo, hi = boxes.lo, boxes.hi
    corners = np.stack([np.where(np.array(bits)[None, :], hi, lo) for bits in np.ndindex(2, 2, 2)], axis=1)  # (B, 8, 3)
    z = np.einsum("bcj,kj->kbc", corners, rots[:, 2, :]) + centers[:, 2, None, None]  # world z of each corner
    return np.all(z > support_z, axis=(1, 2))


def closing_clear(grasps: list[Grasp], boxes: GripperBoxes, margin: float, support_z: float) -> np.ndarray:
    """True where every link, the fingers closing from open down to the grasp's width, stays
    above the support plane (box corners, boxes inflated by ``margin`` m)."""
    ok = np.ones(len(grasps), bool)
    if not grasps or not boxes.samples:
        return ok
    widths = np.array([g.width for g in grasps])
    C = np.array([g.center for g in grasps])
    R = np.array([g.rotation for g in grasps])
    gaps = sorted({s.gap for s in boxes.samples}, reverse=True)
    # group by how far the fingers close: the number of samples at least as wide as the grasp
    reach = np.array([sum(g >= w - CLOSING_TOLERANCE for g in gaps) for w in widths])
    for n in np.unique(reach):
        idx = np.flatnonzero(reach == n)
        sweep = boxes.closing_sweep(gaps[n - 1] if n > 0 else boxes.max_width + 1.0)
        ok[idx] &= above_support(C[idx], R[idx], sweep.inflated(margin), support_z)
    return ok


def linkage_clear(g: Grasp, boxes: GripperBoxes, scene: np.ndarray) -> bool:
    """The closing knuckles and linkages (oriented boxes per measured opening) miss the cloud."""
    if not boxes.samples or len(scene) == 0:
        return True
    near = np.linalg.norm(scene - g.center, axis=1) < 0.25
    return not boxes.linkage_hits((scene[near] - g.center) @ g.rotation, g.width, LINKAGE_MARGIN)


def collision_free(centers, rots, scene, boxes: GripperBoxes, chunk: int = 128) -> np.ndarray:
    """True where no scene point lies inside any of the (swept, inflated) gripper boxes."""
    free = np.ones(len(centers), bool)
    if len(scene) == 0:
        return free
    for a in range(0, len(centers), chunk):
        C, R = centers[a : a + chunk], rots[a : a + chunk]
        local = (scene[None, :, :] - C[:, None, :]) @ R  # (k, S, 3) in each grasp frame
        hit = np.zeros(len(C), bool)
        for lo, hi in zip(boxes.lo, boxes.hi, strict=True):
            hit |= np.any(np.all((local >= lo) & (local <= hi), axis=2), axis=1)
        free[a : a + chunk] = ~hit
    return free
