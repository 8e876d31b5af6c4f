"""Pick-place grasps chosen from the object's real geometry and the gripper's measured geometry.

A parallel gripper grasps top-down: the fingers close across a horizontal direction in which the
whole object (its convex hull, as it lies) is narrower than the measured finger gap less a
clearance, and the grasp height comes from the gripper's own boxes
(:class:`~robocfg.grasp.gripper_model.GripperBoxes`): as low as the object's mid-height when the
gripper allows it, else just low enough that the palm and every other non-finger link whose
footprint covers the object stay above the object's top — so a tall object is gripped near its
top — while the fingertips stay above the support. Closing directions are tried in order of
width (narrowest first), the body's own x and y axes first among equals (a box's faces).

A mesh object first gets the antipodal planner of ``run grasp`` on its own surface (points and
normals sampled from the known mesh: no camera needed); the top-down grasps of its hull follow as
fall-backs. A suction cup grasps the centre of the object's highest flat patch.

Frames: world, metres; grasps in the GraspNet convention (x approach, y closing).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np

from robocfg.assets.object_shape import FINGER_CLEARANCE, ObjectShape
from robocfg.grasp.gripper_model import GripperBoxes
from robocfg.kinematics.frames import Grasp, grasp_rotation

CLEARANCE = FINGER_CLEARANCE
PALM_MARGIN = 0.006  # m: non-finger links kept this far above the object's top
LINKAGE_MARGIN = 0.001  # m: clearance kept between the object and the gripper's non-finger links
HEIGHT_STEP = 0.002  # m: grasp heights tried from mid-height upwards
GROUND_MARGIN = 0.004  # m: fingertips kept this far above the support
MIN_GRIP_DEPTH = 0.008  # m: the pads' lower part reaches at least this far below the object's top
PAD_REACH = 0.01  # m: how far below the TCP the pads count as gripping (half a 2 cm pad), at most their tip
DIRECTIONS = 12  # closing directions tried over half a turn (plus the body's own x and y axes)
SAME_WIDTH = 0.001  # m: widths closer than this count as equal when ordering directions
SURFACE_CHECK_POINTS = 400  # object points the top-down grasp height is checked with
SURFACE_POINTS = 1500  # object points sampled for the antipodal planner
MESH_CANDIDATES = 4  # antipodal grasps handed on to the reach/travel choice
MESH_POOL = 12  # antipodal grasps ranked by their lever arm before MESH_CANDIDATES are kept
LEVER_STEP = 0.005  # m: lever arms closer than this count as equal (the planner's order decides)


@dataclass(frozen=True)
class LyingObject:
    """An object as it lies: ``shape`` (body frame), world ``position`` (m) and ``rotation`` (3x3)
    of its body frame, and the height ``support_z`` (m) of what it rests on."""

    shape: ObjectShape
    position: np.ndarray
    rotation: np.ndarray
    support_z: float

    def points(self) -> np.ndarray:
        """Hull vertices in the world frame (m); computed once per lying object (read-only: the
        grasp search reads them several times)."""
        P = self.__dict__.get("_points")
        if P is None:
            P = self.shape.posed(self.rotation) + self.position
            P.setflags(write=False)
            self.__dict__["_points"] = P
        return P

    def surface_points(self) -> np.ndarray:
        """Points spread over the surface, world frame (m): a fixed sample (same object ⇒ same
        points), for collision tests that vertices alone would miss (a box face)."""
        pts = self.shape.fixed_surface(SURFACE_CHECK_POINTS)
        return np.concatenate([pts @ self.rotation.T + self.position, self.points()])

    @property
    def top_z(self) -> float:
        return float(self.points()[:, 2].max())

    @property
    def bottom_z(self) -> float:
        return float(self.points()[:, 2].min())


def usable_width(boxes: GripperBoxes) -> float:
    """The widest object (m) the open fingers take with ``CLEARANCE`` on each side: the smaller of
    the configured ``max_width`` and the gap measured between the finger boxes."""
    gap = boxes.samples[0].gap if boxes.samples else boxes.max_width
    return min(boxes.max_width, gap if gap > 0 else boxes.max_width) - 2 * CLEARANCE


def top_down_groups(obj: LyingObject, boxes: GripperBoxes) -> list[list[Grasp]]:
    """Top-down grasps grouped by closing direction (each group: the two half-turn twins), best
    direction first; empty when no horizontal direction is narrow enough or the fingers cannot
    reach below the top without their palm touching it."""
    return list(iter_top_down_groups(obj, boxes))


def iter_top_down_groups(obj: LyingObject, boxes: GripperBoxes) -> Iterator[list[Grasp]]:
    """:func:`top_down_groups` one group at a time: a direction's grasp height (the costly part)
    is searched only when its group is asked for (a choice that takes the first reachable group
    seldom needs more than one)."""
    P = obj.points()
    rel = P[:, :2] - obj.position[:2]
    x_axis = obj.rotation[:, 0]
    yaw = math.atan2(x_axis[1], x_axis[0]) if np.hypot(x_axis[0], x_axis[1]) > 1e-6 else 0.0
    angles = [yaw, yaw + math.pi / 2, *(yaw + k * math.pi / DIRECTIONS for k in range(1, DIRECTIONS) if k != DIRECTIONS // 2)]
    w_max = usable_width(boxes)
    options = []
    # a direction's extremes as Python floats (numpy's values: max and min of finite numbers are
    # exact); with a non-finite point, numpy's reductions as before (NaN propagates there)
    finite = bool(np.isfinite(rel).all())
    for order, a in enumerate(angles):
        d = np.array([math.cos(a), math.sin(a)])
        if finite:
            values = (rel @ d).tolist()
            hi, lo = max(values), min(values)
        else:
            proj = rel @ d
            hi, lo = proj.max(), proj.min()
        width = float(hi - lo)
        if width > w_max:
            continue
        mid = float(hi + lo) / 2
        options.append((round(width / SAME_WIDTH), order, a, width, mid))
    fixed = _HeightCheck.of(obj) if options else None
    for _, _, a, width, mid in sorted(options):
        closing = np.array([math.cos(a), math.sin(a), 0.0])
        z = _grasp_height(obj, boxes, closing, width, fixed)
        if z is None:
            continue
        centre = np.array([obj.position[0] + mid * closing[0], obj.position[1] + mid * closing[1], z])
        down = np.array([0.0, 0.0, -1.0])
        yield [Grasp(centre, grasp_rotation(down, s * closing), width) for s in (1.0, -1.0)]


@dataclass(frozen=True)
class _HeightCheck:
    """What every closing direction's height search of one object shares: its surface points and
    the same raised by ``PALM_MARGIN`` (N, 3, world, m), its top and bottom heights (m)."""

    points: np.ndarray
    top: float
    bottom: float

    @classmethod
    def of(cls, obj: LyingObject) -> _HeightCheck:
        P = obj.surface_points()
        return cls(np.concatenate([P, P + np.array([0.0, 0.0, PALM_MARGIN])]), obj.top_z, obj.bottom_z)


def _grasp_height(obj: LyingObject, boxes: GripperBoxes, closing: np.ndarray, width: float,
                  fixed: _HeightCheck | None = None) -> float | None:
    """TCP height (m, world) of a top-down grasp closing along ``closing``: the object's mid-height
    or, where the palm or a linkage would touch the object there (checked on the gripper's
    oriented link boxes at every measured opening down to ``width``, the object raised by
    ``PALM_MARGIN`` too), the lowest height in ``HEIGHT_STEP`` steps where nothing does; the
    fingertips stay ``GROUND_MARGIN`` above the support. None when no clear height leaves the
    pads (down to ``PAD_REACH`` below the TCP, at most to the tip) ``MIN_GRIP_DEPTH`` below the
    object's top. In the grasp frame x points down."""
    R = grasp_rotation(np.array([0.0, 0.0, -1.0]), closing)
    sweep = boxes.closing_sweep(width)
    tip = float(sweep.hi[sweep.finger, 0].max())
    fixed = fixed or _HeightCheck.of(obj)
    top, bottom, P = fixed.top, fixed.bottom, fixed.points
    lowest = max((top + bottom) / 2, obj.support_z + GROUND_MARGIN + tip)
    highest = top - min(MIN_GRIP_DEPTH, (top - bottom) / 2) + min(tip, PAD_REACH)
    centre_xy = obj.position[:2]
    for z in np.arange(lowest, highest + 1e-9, HEIGHT_STEP):
        local = (P - [centre_xy[0], centre_xy[1], z]) @ R
        if not boxes.linkage_hits(local, width, LINKAGE_MARGIN):
            return float(z)
    return None


def mesh_grasps(obj: LyingObject, boxes: GripperBoxes, rng: np.random.Generator, standoff: float,
                reach: Callable[[Grasp], tuple[Grasp, np.ndarray] | None] | None = None) -> list[Grasp]:
    """Antipodal grasps on the object's own surface (at most ``MESH_CANDIDATES``), checked against
    the support and the object itself, and by ``reach`` when given; of the planner's best
    ``MESH_POOL``, those whose closing line passes nearest the centre of mass first (``lever_arm``:
    two pads hold an object against turning about that line by friction alone, so gravity's lever
    about it is what tips the object in the hand), the planner's order among equals."""
    # imported here: only a mesh object needs the planner (its modules cost a pick-place process's
    # start ≈ 1 ms otherwise)
    from robocfg.grasp.antipodal import PlannerSettings, plan_grasps

    pts, nrm = obj.shape.surface(SURFACE_POINTS, rng)
    P = pts @ obj.rotation.T + obj.position
    N = nrm @ obj.rotation.T
    settings = PlannerSettings(standoff=standoff, top_k=MESH_POOL, clearance=CLEARANCE)
    plan = plan_grasps(P, N, P, obj.support_z, boxes, settings, rng, reach=reach)
    grasps = [c.grasp for c in plan.candidates]
    order = sorted(range(len(grasps)), key=lambda i: (round(lever_arm(grasps[i], obj.position) / LEVER_STEP), i))
    return [grasps[i] for i in order[:MESH_CANDIDATES]]


def lever_arm(grasp: Grasp, com: np.ndarray) -> float:
    """Distance (m) from the centre of mass ``com`` (world) to the grasp's closing line (through
    its centre along its y axis)."""
    d = np.asarray(com, float) - grasp.center
    return float(np.linalg.norm(np.cross(d, grasp.rotation[:, 1])))


def suction_grasps(obj: LyingObject, press: float) -> list[Grasp]:
    """Top-down grasps for a suction cup at the centre of the object's highest horizontal patch
    (its hull points within 3 mm of the top), pressed ``press`` m into it; the two differ by a
    half turn about the approach (the cup is round: either will do)."""
    P = obj.points()
    top = P[P[:, 2] >= obj.top_z - 0.003]
    centre = np.array([*top[:, :2].mean(axis=0), obj.top_z - press])
    axis = obj.rotation[:, 0] if abs(obj.rotation[2, 0]) < 0.9 else obj.rotation[:, 1]
    down = np.array([0.0, 0.0, -1.0])
    return [Grasp(centre, grasp_rotation(down, s * axis), 0.0) for s in (1.0, -1.0)]
