"""Is a joint configuration of one arm collision-free? The validity test the global planner samples.

The arm's pinocchio model (:class:`~robocfg.kinematics.model.KinematicModel`: mounted, gripper
open, every other joint locked) carries the robot's URDF collision geometry as convex hulls (what
PyBullet collides too) and the scene's fixed shapes on the universe joint; coal answers
"closer than ``margin``?" for every pair in one pinocchio call, stopping at the first hit, behind
an AABB-tree broad phase (measured 17 µs per check for the Panda in a shelf, 29 µs for the UR5e
with its 2F-85, vs 54 and 139 µs pair by pair). Against a half-space (the ground) the broad phase
lets pairs within ≈ 0.5 mm of the margin pass.

Pairs checked: every moving robot geometry against every scene shape, except supports (ground,
table, pedestal: shapes that are not obstacles) a geometry is already within the margin of at home
(the robot stands on them); robot self pairs whose
geometries hang below different arm joints and are more than ``2·margin`` apart at home (hulls of
neighbouring links overlap at rest: those pairs cannot be told apart from a collision); a held
object (:meth:`CollisionChecker.attach`) against the scene and the arm links that are not part of
the hand holding it. Frames: world, 4×4 transforms, metres; joint values in arm order (rad).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robocfg.collision.shapes import (
    EnvShape,
    LinkGeometry,
    add_environment,
    add_robot_geometry,
    coal_shape,
    to_convex_hulls,
)

if TYPE_CHECKING:
    from robocfg.kinematics.model import KinematicModel

DEFAULT_MARGIN = 0.01  # m: closer than this counts as a collision (tracking error, spline deviation)
HELD = "held:"  # geometry-name prefix of attached objects


@dataclass(frozen=True)
class Contact:
    """A pair closer than the margin: robot-side geometry (link name) and the other side."""

    a: str
    b: str

    def describe(self) -> str:
        return f"{self.a} with {self.b}"


class CollisionChecker:
    """Collision tests for arm configurations of ``kin`` among ``env`` shapes.

    ``links``: the robot's collision geometry (:func:`robocfg.collision.robot_geometry`);
    ``margin`` (m): the clearance every checked pair must keep.
    """

    def __init__(self, kin: KinematicModel, links: list[LinkGeometry], env: list[EnvShape],
                 margin: float = DEFAULT_MARGIN):
        import pinocchio as pin

        self.pin, self.kin, self.margin = pin, kin, float(margin)
        self.model = kin.model
        self.data = self.model.createData()
        self.geom = pin.GeometryModel()
        add_robot_geometry(self.geom, self.model, links)
        to_convex_hulls(self.geom)
        self.robot_ids = [i for i, o in enumerate(self.geom.geometryObjects) if o.parentJoint != 0]
        self.env = {e.name: e for e in env}
        self.env_ids = add_environment(self.geom, env)
        self._held: dict[str, int] = {}
        self.checks = 0  # configurations tested since construction
        self._self_pairs = self._free_self_pairs()
        self._supports = self._support_pairs()
        self._rebuild_pairs()

    # ---- set-up --------------------------------------------------------------------------------
    def _free_self_pairs(self) -> list[tuple[int, int]]:
        """Self pairs under different joints that are clear (> 2·margin) at the home posture."""
        pin = self.pin
        g = self.geom
        g.removeAllCollisionPairs()
        all_robot = [i for i, o in enumerate(g.geometryObjects) if not o.name.startswith("env:")]
        cands = [(a, b) for a in all_robot for b in all_robot
                 if a < b and g.geometryObjects[a].parentJoint != g.geometryObjects[b].parentJoint]
        for a, b in cands:
            g.addCollisionPair(pin.CollisionPair(a, b))
        gdata = pin.GeometryData(g)
        pin.computeDistances(self.model, self.data, g, gdata, np.asarray(self.kin.home, float))
        d = [r.min_distance for r in gdata.distanceResults]
        return [p for p, dist in zip(cands, d, strict=True) if dist > 2 * self.margin]

    def _support_pairs(self) -> set[tuple[int, int]]:
        """(robot geometry, support shape) pairs within the margin at home: not checked."""
        pin = self.pin
        g = self.geom
        g.removeAllCollisionPairs()
        cands = [(r, e) for r in self.robot_ids for name, e in self.env_ids.items() if not self.env[name].obstacle]
        for a, b in cands:
            g.addCollisionPair(pin.CollisionPair(a, b))
        gdata = pin.GeometryData(g)
        pin.computeDistances(self.model, self.data, g, gdata, np.asarray(self.kin.home, float))
        return {p for p, r in zip(cands, gdata.distanceResults, strict=True) if r.min_distance < self.margin}

    def _rebuild_pairs(self) -> None:
        pin = self.pin
        g = self.geom
        g.removeAllCollisionPairs()
        held_ids = set(self._held.values())
        movers = [i for i in self.robot_ids if i not in held_ids]
        for rid in [*movers, *held_ids]:
            for eid in self.env_ids.values():
                if (rid, eid) not in self._supports:
                    g.addCollisionPair(pin.CollisionPair(rid, eid))
        for a, b in self._self_pairs:
            g.addCollisionPair(pin.CollisionPair(a, b))
        for hid in held_ids:  # the held object against arm links not rigid with the hand
            hand_joint = g.geometryObjects[hid].parentJoint
            for rid in movers:
                if g.geometryObjects[rid].parentJoint < hand_joint - 1:
                    g.addCollisionPair(pin.CollisionPair(min(rid, hid), max(rid, hid)))
        self.gdata = pin.GeometryData(g)
        for req in self.gdata.collisionRequests:
            req.security_margin = self.margin
        self.pairs = [(p.first, p.second) for p in g.collisionPairs]
        # an AABB-tree broad phase (boxes inflated by the margin) skips the far pairs: 3–5× faster
        self._broad = pin.BroadPhaseManager_DynamicAABBTreeCollisionManager(self.model, g, self.gdata)
        # is_valid does what pin.computeCollisions(model, data, manager, q, True) does, through the
        # manager's own methods and one kept callback: that overloaded free function is bound for
        # every broad-phase manager type, and boost.python tried ≈ 25 of its signatures per call,
        # each testing the manager argument's type by name (≈ 4.5 of 23 µs a check; same answers)
        self._place = functools.partial(pin.updateGeometryPlacements, self.model, self.data, g, self.gdata)
        self._update, self._collide = self._broad.update, self._broad.collide
        self._callback = pin.CollisionCallBackDefault(g, self.gdata, True)

    # ---- held objects --------------------------------------------------------------------------
    def attach(self, name: str, shape: EnvShape, link: str) -> None:
        """Carry ``shape`` (its ``pose`` given in the ``link`` frame) rigidly with ``link``."""
        pin = self.pin
        if name in self._held:
            self.detach(name)
        frame = self.model.frames[self.model.getFrameId(link)]
        T = np.asarray(shape.pose, float)
        placement = frame.placement * pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())
        obj = pin.GeometryObject(HELD + name, frame.parentJoint, placement, coal_shape(shape))
        self._held[name] = self.geom.addGeometryObject(obj)
        self.robot_ids.append(self._held[name])
        self._rebuild_pairs()

    def detach(self, name: str) -> None:
        """Stop carrying ``name`` (no-op if not attached)."""
        gid = self._held.pop(name, None)
        if gid is None:
            return
        self.geom.removeGeometryObject(HELD + name)
        self.robot_ids = [i for i, o in enumerate(self.geom.geometryObjects) if o.parentJoint != 0]
        self._self_pairs = [(a, b) for a, b in self._self_pairs if gid not in (a, b)]
        self._self_pairs = [(a - (a > gid), b - (b > gid)) for a, b in self._self_pairs]
        self._supports = {(a - (a > gid), b - (b > gid)) for a, b in self._supports}
        self.env_ids = {k: v - (v > gid) for k, v in self.env_ids.items()}
        self._held = {k: v - (v > gid) for k, v in self._held.items()}
        self._rebuild_pairs()

    def move_shape(self, name: str, pose: np.ndarray) -> None:
        """Put scene shape ``name`` at ``pose`` (4×4, world), e.g. a loose object that was pushed."""
        from robocfg.collision.shapes import set_environment_pose

        self.env[name].pose = np.asarray(pose, float)
        set_environment_pose(self.geom, self.env_ids[name], pose)

    @property
    def held(self) -> list[str]:
        return list(self._held)

    # ---- queries -------------------------------------------------------------------------------
    def is_valid(self, q: np.ndarray) -> bool:
        """True if every checked pair keeps ``margin`` at joint values ``q`` (arm order, rad)."""
        self.checks += 1
        self._place(np.asarray(q, float))
        self._update(False)
        cb = self._callback
        self._collide(cb)  # coal's collide starts with cb.init()
        cb.done()
        return not cb.collision

    def contacts(self, q: np.ndarray) -> list[Contact]:
        """Every pair closer than ``margin`` at ``q``, named by link / scene shape."""
        self.pin.computeCollisions(self.model, self.data, self.geom, self.gdata, np.asarray(q, float), False)
        out = []
        for k, res in enumerate(self.gdata.collisionResults):
            if res.isCollision():
                a, b = self.pairs[k]
                out.append(Contact(self._label(a), self._label(b)))
        return out

    def clearance(self, q: np.ndarray, scene_only: bool = False) -> float:
        """Smallest distance (m) over the checked pairs at ``q`` (negative: penetration);
        ``scene_only``: over the pairs with a scene shape only (no self pairs)."""
        pin = self.pin
        pin.computeDistances(self.model, self.data, self.geom, self.gdata, np.asarray(q, float))
        env = set(self.env_ids.values())
        return min((r.min_distance for (_, b), r in zip(self.pairs, self.gdata.distanceResults, strict=True)
                    if not scene_only or b in env), default=float("inf"))

    def segment_valid(self, qa: np.ndarray, qb: np.ndarray, step: float) -> bool:
        """True if the straight joint-space segment qa → qb is valid at every ``step`` (rad, max-norm)
        and at both ends, tested middle-first so that a blocked segment is rejected early."""
        qa, qb = np.asarray(qa, float), np.asarray(qb, float)
        n = max(1, int(np.ceil(float(np.max(np.abs(qb - qa))) / step)))
        states = qa + (qb - qa) * (_bisection_order(n)[:, None] / n)  # all at once: the same values
        return all(self.is_valid(q) for q in states)

    def _label(self, gid: int) -> str:
        name = self.geom.geometryObjects[gid].name
        if name.startswith("env:"):
            return name[4:]
        if name.startswith(HELD):
            return f"held object {name[len(HELD):]!r}"
        return name.rsplit("_", 1)[0]  # link name (geometries are named link_index)


@functools.lru_cache(maxsize=256)
def _bisection_order(n: int) -> np.ndarray:
    """0..n, ends first, then midpoints of ever finer halves (cached: segments of a path repeat
    their lengths, and building the order in Python cost ≈ 0.2 ms per segment)."""
    order, seen = [0, n], {0, n}
    spans = [(0, n)]
    while spans:
        nxt = []
        for a, b in spans:
            if b - a > 1:
                m = (a + b) // 2
                if m not in seen:
                    seen.add(m)
                    order.append(m)
                nxt += [(a, m), (m, b)]
        spans = nxt
    out = np.asarray(order, float)
    out.flags.writeable = False
    return out
