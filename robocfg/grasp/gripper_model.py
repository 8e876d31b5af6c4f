"""A box model of the gripper in the grasp frame, measured from the robot's own collision shapes.

Every link rigidly or movably attached below ``ee_link`` (and ``ee_link`` itself) becomes one
axis-aligned box in the GraspNet grasp frame (origin at the TCP, x = approach, y = closing,
z = x × y), measured with the gripper open, and again at ``CLOSING_SAMPLES``
openings down to closed (with an oriented box per link, for linkages). No per-robot numbers: the
boxes come from PyBullet's collision shapes (mesh vertices and primitive corners), so any robot
YAML works. A cloud point inside a box means the gripper would hit it; extending the boxes back
along −x by the pre-grasp stand-off covers the straight approach too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robocfg.config.robot import ParallelGripperConfig
from robocfg.config.types import AXIS_INDEX

if TYPE_CHECKING:
    from robocfg.config.robot import ArmConfig
    from robocfg.sim.link_boxes import LinkBoxes, OrientedBox
    from robocfg.sim.robot import ArmHandle, RobotHandle

CLOSING_SAMPLES = 9  # openings measured from open to closed (a Robotiq's pads move ≈ 10 mm between samples)
CLOSING_TOLERANCE = 0.005  # m: a sample this much narrower than the grasp width still counts as reached
# m: added to a link box's bounds in the grasp frame before the object's bounds are compared with
# them (linkage_hits): far beyond the rounding of the box test's few operations on values < 10 m
BOUNDS_SLACK = 1e-6


@dataclass(frozen=True)
class GripperSample:
    """The gripper measured at one opening: finger ``gap`` (m), per-link boxes ``lo``/``hi`` (B, 3)
    in the grasp frame and oriented boxes. Linkages such as the Robotiq's swing their pads
    forward as they close, so what sweeps below the TCP depends on the width."""

    gap: float
    lo: np.ndarray
    hi: np.ndarray
    obbs: tuple[OrientedBox, ...]

    def bounds(self, margin: float) -> list[tuple[list[float], list[float]]]:
        """Per oriented box, its bounds in the grasp frame grown by ``margin`` (see
        :func:`_grasp_frame_bounds`), computed once per margin (the sample is measured once a world)."""
        kept: dict[float, list[tuple[list[float], list[float]]]] = self.__dict__.setdefault("_bounds", {})
        out = kept.get(margin)
        if out is None:
            out = kept[margin] = [_grasp_frame_bounds(obb, margin) for obb in self.obbs]
        return out


@dataclass(frozen=True)
class GripperBoxes:
    """``lo``, ``hi`` (B, 3): box corners in the grasp frame (m); ``names``: link per box;
    ``finger``: which boxes are finger links; ``max_width``: open finger gap (m)."""

    lo: np.ndarray
    hi: np.ndarray
    names: tuple[str, ...]
    finger: np.ndarray
    max_width: float
    samples: tuple[GripperSample, ...] = ()  # from open to closed

    def linkage_hits(self, points_g: np.ndarray, width: float, margin: float) -> bool:
        """True if a non-finger link, at any measured opening down to ``width`` (m), has one of
        ``points_g`` (N, 3, grasp frame) inside its oriented box grown by ``margin``.

        A link box whose axis-aligned bounds in the grasp frame (grown by ``margin`` and
        ``BOUNDS_SLACK``) do not meet the points' bounds holds none of them: it is passed over
        without testing the points one by one (the answer is the same; a box the object is far
        from costs a few float comparisons instead of the points' transform)."""
        cloud: tuple[list[float], list[float]] | None = None
        for s in self.samples:
            if s.gap < width:
                continue
            for i, (R, t, lo, hi, touches) in enumerate(s.obbs):
                if touches:
                    continue
                if cloud is None:
                    if len(points_g) == 0:
                        return False
                    cloud = points_g.min(axis=0).tolist(), points_g.max(axis=0).tolist()
                (blo, bhi), (clo, chi) = s.bounds(margin)[i], cloud
                if any(chi[k] < blo[k] or clo[k] > bhi[k] for k in range(3)):
                    continue
                local = (points_g - t) @ R
                if np.any(np.all((local >= lo - margin) & (local <= hi + margin), axis=1)):
                    return True
        return False

    def closing_sweep(self, width: float | None = None) -> GripperBoxes:
        """Each link's box grown to cover it from open until the fingers reach ``width`` (m;
        None: fully closed) — for support-plane checks of the closing motion. Made once per set of
        openings it covers (the same samples give the same boxes; read-only: every episode's
        grasp search asks for it)."""
        used = tuple(i for i, s in enumerate(self.samples) if width is None or s.gap >= width - CLOSING_TOLERANCE)
        kept: dict[tuple[int, ...], GripperBoxes] = self.__dict__.setdefault("_sweeps", {})
        out = kept.get(used)
        if out is None:
            lo, hi = self.lo.copy(), self.hi.copy()
            for i in used:
                lo, hi = np.minimum(lo, self.samples[i].lo), np.maximum(hi, self.samples[i].hi)
            lo.setflags(write=False)
            hi.setflags(write=False)
            out = kept[used] = GripperBoxes(lo, hi, self.names, self.finger, self.max_width)
        return out

    def swept(self, standoff: float) -> GripperBoxes:
        """Boxes covering the straight motion from ``standoff`` m back along the approach."""
        lo = self.lo.copy()
        lo[:, 0] -= standoff
        return GripperBoxes(lo, self.hi, self.names, self.finger, self.max_width, self.samples)

    def inflated(self, margin: float) -> GripperBoxes:
        return GripperBoxes(self.lo - margin, self.hi + margin, self.names, self.finger, self.max_width, self.samples)

    def finger_depth(self) -> tuple[float, float]:
        """Approach-axis extent (x range, m) of the fingers: where they can touch the object."""
        return float(self.lo[self.finger, 0].max()), float(self.hi[self.finger, 0].min())

    def finger_height(self) -> tuple[float, float]:
        """z range (m) shared by the fingers (their width across the closing direction)."""
        return float(self.lo[self.finger, 2].max()), float(self.hi[self.finger, 2].min())


def _grasp_frame_bounds(obb: OrientedBox, margin: float) -> tuple[list[float], list[float]]:
    """(min corner, max corner) (m, grasp frame) bounding the oriented box ``obb`` grown by
    ``margin``, widened by ``BOUNDS_SLACK``: a point the box test (``(p − t)·R`` within
    ``[lo − margin, hi + margin]``) finds inside lies within them whatever the rounding, so a
    point set outside them has no point in the box."""
    R, t, lo, hi = (np.asarray(a, dtype=float).tolist() for a in obb[:4])
    mid = [(a + b) / 2 for a, b in zip(lo, hi, strict=True)]
    half = [(b - a) / 2 + margin + BOUNDS_SLACK for a, b in zip(lo, hi, strict=True)]
    centre = [t[k] + sum(R[k][j] * mid[j] for j in range(3)) for k in range(3)]
    ext = [sum(abs(R[k][j]) * half[j] for j in range(3)) + BOUNDS_SLACK for k in range(3)]
    return [c - e for c, e in zip(centre, ext, strict=True)], [c + e for c, e in zip(centre, ext, strict=True)]


def measure_gripper(robot: RobotHandle, arm: ArmHandle) -> GripperBoxes:
    """Boxes of ``arm``'s gripper measured open, then at ``CLOSING_SAMPLES`` openings down to closed
    (the gripper is teleported and back open: call it before taking a snapshot). Links without a
    collision shape are skipped; finger links are the gripper's ``finger_links``."""
    from robocfg.sim.link_boxes import gripper_layout, measure_link_boxes

    g = arm.gripper
    G_T_ee = grasp_from_ee(arm.config)
    layout = gripper_layout(robot, arm)  # links and shapes, read once for all the openings
    m = measure_link_boxes(robot, arm, G_T_ee, layout)
    lo, hi, names, finger = m.lo, m.hi, m.names, m.finger
    samples = [_sample(m, finger)]
    if g is not None:
        for f in np.linspace(1.0, 0.0, CLOSING_SAMPLES)[1:]:
            g.reset(float(f))
            s = measure_link_boxes(robot, arm, G_T_ee, layout)
            if s.names == names:
                samples.append(_sample(s, finger))
        g.reset(1.0)
    g_cfg = arm.config.gripper
    max_width = g_cfg.max_width if isinstance(g_cfg, ParallelGripperConfig) else 0.0
    return GripperBoxes(lo, hi, names, finger, max_width, tuple(samples))


def _sample(m: LinkBoxes, finger: np.ndarray) -> GripperSample:
    return GripperSample(_gap(m.lo, m.hi, finger), m.lo, m.hi, m.obbs)


def _gap(lo: np.ndarray, hi: np.ndarray, finger: np.ndarray) -> float:
    """Gap (m) between the finger boxes along the closing axis (y), 0 when they overlap."""
    lo_y, hi_y = lo[finger, 1], hi[finger, 1]
    pos, neg = lo_y[lo_y + hi_y > 0], hi_y[lo_y + hi_y < 0]
    return max(0.0, float(pos.min() - neg.max())) if len(pos) and len(neg) else 0.0


def grasp_from_ee(cfg: ArmConfig) -> np.ndarray:
    """grasp_T_ee (4x4): world_R_ee = world_R_grasp · R_ee_graspnet, TCP at tcp_offset along ee_axis."""
    R = np.asarray(cfg.R_ee_graspnet, float)
    tcp = np.zeros(3)
    tcp[AXIS_INDEX[cfg.ee_axis]] = cfg.tcp_offset
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = -R @ tcp
    return T
