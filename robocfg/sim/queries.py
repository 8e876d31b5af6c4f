"""What runners ask the physics besides stepping: ray casts, contacts, closest points, AABBs,
dynamics changes, debug markers and GUI sliders — so that only ``robocfg.sim`` imports PyBullet.

:class:`SceneQueries` is mixed into :class:`robocfg.sim.world.World`; every method takes bodies
by name or id. World frame, metres.
"""

from __future__ import annotations

from collections.abc import Collection, Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import pybullet as p

GUI_ERROR = p.error  # raised by GUI calls once the window is closed
JUMP_CLEARANCE = 0.01  # m: a walk that jumps skipped bodies starts this far short of any other body's box


@dataclass(frozen=True)
class RayHit:
    """Where a ray met a body: its id and the hit point (world, m)."""

    body: int
    position: tuple[float, float, float]


@dataclass(frozen=True)
class PairPoint:
    """A closest point or contact between body ``a`` (link ``link_a``; −1 = base) and body ``b``;
    ``distance`` (m) is negative when they penetrate."""

    link_a: int
    link_b: int
    distance: float


def _segment(start: Sequence[float], end: Sequence[float]) -> tuple[list[float], list[float], float, list[float]]:
    """(start, end, length m, unit direction) of a segment as Python floats, with the bits of
    ``a, b = np.asarray(start, float), np.asarray(end, float)``, ``float(np.linalg.norm(b - a))``
    and ``((b - a) / length).tolist()``. Where at most one coordinate changes along the segment
    (the support queries' vertical rays) the length is that coordinate's |difference| without a
    numpy call: numpy's norm is the square root of a dot product whose other terms are zero, and
    in binary floating point the square root of a correctly rounded square gives back the
    magnitude exactly (within the range checked here: no overflow or underflow of the square)."""
    if len(start) != 3 or len(end) != 3:
        raise ValueError(f"a segment needs two 3-D points, got {len(start)} and {len(end)} coordinates")
    x0, y0, z0 = start
    x1, y1, z1 = end
    a = [float(x0), float(y0), float(z0)]
    b = [float(x1), float(y1), float(z1)]
    dx, dy, dz = diff = [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
    if dx == 0.0 and dy == 0.0:
        length = abs(dz)
    elif dx == 0.0 and dz == 0.0:
        length = abs(dy)
    elif dy == 0.0 and dz == 0.0:
        length = abs(dx)
    else:
        length = -1.0
    if not (length == 0.0 or 1e-150 < length < 1e150):  # two or more coordinates change, or out of range
        length = float(np.linalg.norm(np.array(diff)))
    if length == 0.0:
        return a, b, 0.0, diff
    return a, b, length, [dx / length, dy / length, dz / length]


class SceneQueries:
    """Physics queries of a world (needs ``client`` and ``body_id``)."""

    client: int

    def body_id(self, name_or_id: str | int) -> int:  # provided by World
        raise NotImplementedError

    def ray_hits(self, start: Sequence[float], end: Sequence[float], max_hits: int = 16) -> list[RayHit]:
        """Every body (link) the segment ``start`` → ``end`` passes through, nearest first.

        A PyBullet ray reports its closest hit only, so after each hit the ray is cast again from
        just past that hit point (an object resting on a fixture would otherwise hide the fixture).
        A ray starting inside a shape may report that shape again at its start (primitive links of
        a robot do; a decomposed mesh's convex parts do not): while the same link answers, the step
        past the hit doubles from 0.1 mm, never beyond the link's bounding box. Restarting past the
        bounding box at once skipped thin supports: a mesh's box carries Bullet's collision margin
        and reached through the top of a 5 cm stand under it."""
        return list(self._ray_walk(start, end, max_hits))

    def first_ray_hit(self, start: Sequence[float], end: Sequence[float], skip: Collection[int] = (),
                      max_hits: int = 16, *, jump_skipped: bool = False) -> RayHit | None:
        """The first hit of :meth:`ray_hits` (same arguments) whose body is not in ``skip`` (None
        when there is none): the casts stop there, those past it are not made.

        ``jump_skipped``: the walk starts past skipped bodies that the ray meets before any other
        body's bounding box (:meth:`_past_skipped`), instead of casting through them (a robot arm
        above the point: 3–4 casts a link). The same surface is found, but its hit point may
        differ from a walk from ``start`` in the last bits (a cast's fraction depends on where it
        starts): for answers that only go to a tolerance check. The bodies ahead are found in
        PyBullet's broadphase (``getOverlappingObjects``), whose boxes are brought up to date by a
        physics step (``stepSimulation``, or ``performCollisionDetection``) and not by a teleport: a
        caller that has moved a body (``resetBasePositionAndOrientation``, a joint reset, a
        restore) and casts before the world has stepped must not pass ``jump_skipped`` (a body
        moved into the ray since the last step is not listed, and the jump could start past its
        surface)."""
        if jump_skipped and skip:
            start = self._past_skipped(start, end, skip)
        for hit in self._ray_walk(start, end, max_hits):
            if hit.body not in skip:
                return hit
        return None

    def _past_skipped(self, start: Sequence[float], end: Sequence[float], skip: Collection[int]) -> Sequence[float]:
        """Where a walk from ``start`` to ``end`` may start instead, having met only bodies in
        ``skip`` before: a point of the segment :data:`JUMP_CLEARANCE` short of the first bounding
        box (Bullet's, margin included: no surface lies outside it) of a body not in ``skip``, or
        0.1 mm short of the skipped box it lies in (stepped back while it lies in one), so that the
        cast starts outside every box, as one from ``start`` does. (A cast starting within about a
        millimetre of a convex shape reports a hit *at its start*: 0.1 mm short of a table's box
        gave a height 0.1 mm too high; a skipped body's such hit is walked through.) ``start``
        itself when no skipped box lies wholly before that point (nothing to jump: the walk is then
        the same, bit for bit). The broadphase it asks is only current after a physics step (see
        :meth:`first_ray_hit`)."""
        a0, b0, length, d = _segment(start, end)
        if length == 0.0:
            return start
        c = self.client
        pairs = p.getOverlappingObjects([min(u, v) for u, v in zip(a0, b0, strict=True)],
                                        [max(u, v) for u, v in zip(a0, b0, strict=True)], physicsClientId=c)
        skipped: list[tuple[float, float]] = []  # (entry, exit) along the ray (m from start)
        first_other = length
        moving = [(k, a0[k], d[k]) for k in range(3) if abs(d[k]) >= 1e-12]
        still = [(k, a0[k]) for k in range(3) if abs(d[k]) < 1e-12]
        for body, link in pairs or ():
            lo, hi = p.getAABB(body, link, physicsClientId=c)
            if any(not lo[k] <= ak <= hi[k] for k, ak in still):
                continue
            t0, t1 = 0.0, length  # the slab test: the segment's part inside the box
            for k, ak, dk in moving:
                u, v = (lo[k] - ak) / dk, (hi[k] - ak) / dk
                if u > v:
                    u, v = v, u
                if u > t0:
                    t0 = u
                if v < t1:
                    t1 = v
            if t0 > t1:  # the segment misses this box
                continue
            if body in skip:
                skipped.append((t0, t1))
            else:
                first_other = min(first_other, t0)
        t = first_other - JUMP_CLEARANCE
        moved = True
        while moved:  # step back out of skipped boxes the point lies in
            moved = False
            for t0, t1 in skipped:
                if t0 <= t <= t1:
                    t, moved = t0 - 1e-4, True
        if t <= 0.0 or not any(t1 < t for _, t1 in skipped):
            return start
        return [a0[k] + t * d[k] for k in range(3)]

    def _ray_walk(self, start: Sequence[float], end: Sequence[float], max_hits: int) -> Iterator[RayHit]:
        """:meth:`ray_hits`'s hits, nearest first, each cast made when the previous hit has been taken."""
        a, to, length, d = _segment(start, end)
        if length == 0.0:
            return
        # Python floats from here (the same IEEE operations as the arrays' element by element,
        # without numpy's per-call cost on 3-vectors): the direction, and the ray's start per cast
        dx, dy, dz = d
        ax, ay, az = a
        axes = [k for k in range(3) if abs(d[k]) > 1e-12]
        ray, aabb, c = p.rayTest, p.getAABB, self.client
        found = 0
        seen: set[tuple[int, int]] = set()
        boxes: dict[tuple[int, int], tuple] = {}
        s, step, last = [ax, ay, az], 1e-4, (-1, -1)
        for _ in range(8 * max_hits):
            h = ray(s, to, physicsClientId=c)[0]
            if h[0] < 0:
                break
            key = (h[0], h[1])
            step = 2.0 * step if key == last else 1e-4
            last = key
            hx, hy, hz = hit = h[3]
            if key not in seen:
                seen.add(key)
                found += 1
                yield RayHit(key[0], (hx, hy, hz))
                if found >= max_hits:
                    break
            box = boxes.get(key)
            if box is None:  # nothing moves during a walk: a link's box is read once
                box = boxes[key] = aabb(h[0], h[1], physicsClientId=c)
            lo, hi = box
            exits = [((hi[k] if d[k] > 0 else lo[k]) - hit[k]) / d[k] for k in axes]
            m = min(step, max(min(exits), 0.0) + 1e-4)
            s = [hx + m * dx, hy + m * dy, hz + m * dz]
            if (s[0] - ax) * dx + (s[1] - ay) * dy + (s[2] - az) * dz >= length:
                break

    def closest_points(self, a: str | int, b: str | int, max_distance: float) -> list[PairPoint]:
        """Closest points of bodies ``a`` and ``b`` nearer than ``max_distance`` (m), per link pair."""
        pts = p.getClosestPoints(self.body_id(a), self.body_id(b), max_distance, physicsClientId=self.client)
        return [PairPoint(int(c[3]), int(c[4]), float(c[8])) for c in pts]

    def contact_points(self, a: str | int, b: str | int) -> list[PairPoint]:
        """Contacts of the last physics step between bodies ``a`` and ``b``."""
        pts = p.getContactPoints(self.body_id(a), self.body_id(b), physicsClientId=self.client)
        return [PairPoint(int(c[3]), int(c[4]), float(c[8])) for c in pts]

    def refresh_contacts(self, a: str | int, b: str | int, links_a: Sequence[int]) -> None:
        """Rebuild the contact points between links ``links_a`` of body ``a`` and body ``b`` from
        their current geometry; no simulated time passes and no body moves.

        Bullet keeps each pair's contact points across steps (a persistent manifold) and only
        re-measures a kept point's depth along the normal it was created with; a point whose
        normal came out turned round (a box edge resolved inside a finger's convex hull) is then
        kept as the deepest one and pushes the finger *into* the body: measured on the Panda, both
        fingers stalled 0.5 mm off a released box with 15–19 N on such points, for as long as the
        run lasted. The pair is left out of one collision pass (its manifold is dropped) and
        collided again (a second pass: the contact queries and the next step see contacts of the
        geometry as it is)."""
        ia, ib, c = self.body_id(a), self.body_id(b), self.client
        for link in links_a:
            p.setCollisionFilterPair(ia, ib, link, -1, 0, physicsClientId=c)
        p.performCollisionDetection(physicsClientId=c)
        for link in links_a:
            p.setCollisionFilterPair(ia, ib, link, -1, 1, physicsClientId=c)
        p.performCollisionDetection(physicsClientId=c)

    def touching(self, a: str | int, b: str | int, links_a: Sequence[int]) -> bool:
        """Whether a contact point of the last step between links ``links_a`` of ``a`` and body
        ``b`` is at distance ≤ 0 (touching or penetrating)."""
        ia, ib = self.body_id(a), self.body_id(b)
        links = set(links_a)  # one query of a's contacts with b (PyBullet puts the asked body A first), by link
        return any(c[8] <= 0.0 and c[3] in links for c in p.getContactPoints(ia, ib, physicsClientId=self.client))

    def aabb(self, body: str | int, link: int = -1) -> tuple[np.ndarray, np.ndarray]:
        """(min corner, max corner) of a body's (or link's) axis-aligned bounding box (world, m)."""
        lo, hi = p.getAABB(self.body_id(body), link, physicsClientId=self.client)
        return np.asarray(lo), np.asarray(hi)

    def set_dynamics(self, body: str | int, link: int = -1, *, rolling_friction: float | None = None,
                     spinning_friction: float | None = None, lateral_friction: float | None = None,
                     mass: float | None = None) -> None:
        """Change a body's dynamics; only the given values change (frictions unitless or m, mass kg)."""
        kw = {k: v for k, v in (("rollingFriction", rolling_friction), ("spinningFriction", spinning_friction),
                                ("lateralFriction", lateral_friction), ("mass", mass)) if v is not None}
        p.changeDynamics(self.body_id(body), link, physicsClientId=self.client, **kw)

    def add_marker(self, position: Sequence[float], radius: float = 0.015,
                   rgba: Sequence[float] = (0.1, 0.8, 0.2, 0.8)) -> int:
        """A sphere without collision, to show a point (GUI and recordings); returns its body id."""
        vis = p.createVisualShape(p.GEOM_SPHERE, radius=radius, rgbaColor=list(rgba), physicsClientId=self.client)
        return int(p.createMultiBody(0.0, -1, vis, [float(v) for v in position], physicsClientId=self.client))

    def add_slider(self, label: str, low: float, high: float, value: float) -> int:
        """A GUI slider (the debug panel is switched on); read it with :meth:`read_slider`."""
        p.configureDebugVisualizer(p.COV_ENABLE_GUI, 1, physicsClientId=self.client)
        return int(p.addUserDebugParameter(label, low, high, value, physicsClientId=self.client))

    def read_slider(self, slider: int) -> float:
        """The slider's value; raises :data:`GUI_ERROR` once the GUI window is closed."""
        return float(p.readUserDebugParameter(slider, physicsClientId=self.client))
