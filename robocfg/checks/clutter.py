"""Checks of a ``pick_place_many`` task before simulating, and the place spots its objects take.

Before anything is simulated: the place target names a bin or a shelf level that exists; that
target holds every object (:func:`place_spots`); no object's randomisation region, swept by the
object's footprint, reaches into a fixture part or into another object's region. (Objects
spawned inside a fixture at their nominal pose, and names clashing with the scene's, are found by
:func:`robocfg.checks.scene.check_scene`, which gets these objects too.) Whether the arm reaches
the objects and the spots is checked by IK when the run starts (the runner's ``check``).

Frames: world, metres. An object's *footprint radius* is the largest horizontal distance of its
hull from its centre (any yaw), so spots and regions that keep footprints apart keep the objects
apart however they are turned.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robocfg.checks.scene import TOLERANCE, _Box, _box, overlap_depth
from robocfg.config.fixtures import BinFixture, ShelfFixture
from robocfg.config.load import YamlDocument
from robocfg.config.multi_pick import PickObject, PickPlaceManyParams, PlaceInto
from robocfg.config.scene import Scene
from robocfg.errors import Problem

Loc = tuple[str | int, ...]
BLOCK = ("pick_place_many",)


@dataclass(frozen=True)
class PlaceSpots:
    """The spots of a place target: centres (k, 3) on the support's top face (m, world), the
    horizontal unit vector out of the target through its open side (a shelf's front; zero for a
    bin, open upwards) and the height of the underside of the board above a shelf level (m, world;
    None for a bin)."""

    points: np.ndarray
    front: np.ndarray
    ceiling: float | None


def footprint_radius(body: PickObject, base_dir: Path) -> float:
    """Largest horizontal distance (m) of the object's hull from its centre, for any yaw."""
    from robocfg.assets.object_shape import object_shape
    from robocfg.geometry import quat_to_matrix

    pts = object_shape(body, base_dir).posed(quat_to_matrix(body.quaternion_xyzw()))
    return float(np.max(np.linalg.norm(pts[:, :2], axis=1)))


def place_fixture(scene: Scene, place: PlaceInto) -> BinFixture | ShelfFixture | None:
    f = next((f for f in scene.fixtures if f.name == place.fixture), None)
    return f if isinstance(f, BinFixture | ShelfFixture) else None


def place_spots(scene: Scene, place: PlaceInto, radius: float) -> PlaceSpots:
    """Every spot of ``place`` (a bin's floor or a shelf board) where an object of footprint
    ``radius`` (m) keeps ``place.gap`` from the walls and from objects on the neighbouring spots:
    a grid of pitch 2·radius + gap, centred; a shelf board gets one row at ``place.depth``. The
    spots come middle first (by distance from the grid's centre; ties in grid order)."""
    from robocfg.geometry import pose_matrix

    f = place_fixture(scene, place)
    if f is None:
        raise ValueError(f"{place.fixture!r} is not a bin or shelf of the scene")
    x, y, z = f.size
    pitch = 2 * radius + place.gap
    if isinstance(f, BinFixture):
        hx, hy = _bin_reach(f, place, radius)
        xs, ys, h, ceiling = _row(hx, pitch), _row(hy, pitch), f.floor_height(), None
        front = np.zeros(3)
    else:
        hy = y / 2 - f.board - place.gap - radius
        heights = f.level_heights()
        h = heights[place.level]
        ceiling = [*f.levels, z][place.level] - f.board  # the underside of the board above
        x_in = -x / 2 + place.depth * (x - f.board)
        xs, ys = np.array([x_in]), _row(hy, pitch)
        front = np.array([-1.0, 0.0, 0.0])
    T = pose_matrix(f)
    local = np.array([[a, b, h, 1.0] for a in xs for b in ys]).reshape(-1, 4)
    # middle spots first (stable): away from the walls and sides, where an arm has the most room
    local = local[np.argsort(np.hypot(local[:, 0] - (xs.mean() if len(xs) else 0.0), local[:, 1]), kind="stable")]
    pts = (T @ local.T).T[:, :3]
    return PlaceSpots(pts, T[:3, :3] @ front, None if ceiling is None else float(T[2, 3] + ceiling))


# the off-grid lattice's pitch as a share of the grid's (2·radius + gap)
OFF_GRID_PITCH = 0.25


def bin_lattice(scene: Scene, place: PlaceInto, radius: float) -> np.ndarray:
    """Centres (k, 3; m, world, on the bin's floor) of a finer lattice than :func:`place_spots`'
    grid (pitch ``OFF_GRID_PITCH``·(2·radius + gap), centred like the grid; a grid spot lies on it
    only when the two rows have the same parity, and the spots tried already are skipped by
    :func:`off_grid_spots` either way) where an object of footprint ``radius`` keeps ``place.gap``
    from the bin's walls; in grid order. Empty for a shelf."""
    from robocfg.geometry import pose_matrix

    f = place_fixture(scene, place)
    if not isinstance(f, BinFixture):
        return np.zeros((0, 3))
    pitch = OFF_GRID_PITCH * (2 * radius + place.gap)
    hx, hy = _bin_reach(f, place, radius)
    local = np.array([[a, b, f.floor_height(), 1.0] for a in _row(hx, pitch) for b in _row(hy, pitch)]).reshape(-1, 4)
    return (pose_matrix(f) @ local.T).T[:, :3]


def off_grid_spots(lattice: np.ndarray, near: np.ndarray, radius: float, gap: float,
                   placed: list[tuple[np.ndarray, float]], tried: list[np.ndarray]) -> list[np.ndarray]:
    """Points (x, y; m, world) of ``lattice`` (k, ≥2) where an object of footprint ``radius``
    keeps ``gap`` from every ``placed`` object (its centre x, y and footprint radius, m) and that
    are none of the ``tried`` spots; nearest to ``near`` first (ties in lattice order)."""
    out = []
    for p in lattice[:, :2]:
        if any(float(np.linalg.norm(p - np.asarray(t, float)[:2])) < 1e-6 for t in tried):
            continue
        if all(float(np.linalg.norm(p - np.asarray(c, float)[:2])) >= radius + r + gap for c, r in placed):
            out.append(p.copy())
    order = np.argsort([float(np.linalg.norm(p - near[:2])) for p in out], kind="stable")
    return [out[i] for i in order]


def overlapped(xy: np.ndarray, radius: float, spots: np.ndarray, spot_radius: float, gap: float) -> np.ndarray:
    """Which of ``spots`` (k, ≥2; m) an object of footprint ``radius`` at ``xy`` comes within
    ``gap`` of, an object of footprint ``spot_radius`` standing on each (bool, k)."""
    d = np.linalg.norm(np.asarray(spots, float)[:, :2] - np.asarray(xy, float)[:2], axis=1)
    return np.asarray(d < radius + spot_radius + gap - 1e-9)


def _bin_reach(f: BinFixture, place: PlaceInto, radius: float) -> tuple[float, float]:
    """How far (m, along the bin's x and y) from the bin's centre an object of footprint
    ``radius`` may stand and keep ``place.gap`` from the inner faces of its walls."""
    x, y, _ = f.size
    return x / 2 - f.wall - place.gap - radius, y / 2 - f.wall - place.gap - radius


def _row(half: float, pitch: float) -> np.ndarray:
    """Centres of a row of spots ``pitch`` apart within ±``half`` (m), centred on 0."""
    if half < 0:
        return np.zeros(0)
    n = math.floor(2 * half / pitch + 1e-9) + 1
    return (np.arange(n) - (n - 1) / 2) * pitch


def check_many(doc: YamlDocument, scene: Scene, params: PickPlaceManyParams) -> list[Problem]:
    """Problems of a pick_place_many task's place target and object regions (see the module doc)."""
    problems: list[Problem] = []
    place = params.place
    loc_place = (*BLOCK, "place")
    f = next((f for f in scene.fixtures if f.name == place.fixture), None)
    if f is None:
        names = [f.name for f in scene.fixtures]
        from robocfg.suggest import did_you_mean

        return [doc.problem((*loc_place, "fixture"), f"no fixture {place.fixture!r} in scene.fixtures"
                            f"{did_you_mean(place.fixture, names)}; known: {', '.join(names) or 'none'}")]
    if not isinstance(f, BinFixture | ShelfFixture):
        return [doc.problem((*loc_place, "fixture"), f"fixture {f.name!r} is a {f.type}: objects go into a bin or onto a shelf")]
    if isinstance(f, ShelfFixture) and place.level > len(f.levels):
        return [doc.problem((*loc_place, "level"), f"shelf {f.name!r} has levels 0..{len(f.levels)} (0 = bottom board), got {place.level}")]
    base = doc.path.parent
    radii = [footprint_radius(o, base) for o in params.objects]
    spots = place_spots(scene, place, max(radii))
    if len(spots.points) < len(params.objects):
        problems.append(doc.problem((*loc_place, "gap"), f"{f.name!r} holds {len(spots.points)} of the "
                                    f"{len(params.objects)} objects ({max(radii) * 1000:.0f} mm footprint radius, "
                                    f"gap {place.gap * 1000:.0f} mm)"))
    regions = [_region_box(o, r, (*BLOCK, "objects", k, "region"), base) for k, (o, r) in enumerate(zip(params.objects, radii, strict=True))]
    parts = [_box(p, ("scene", "fixtures", k)) for k, fx in enumerate(scene.fixtures) for p in fx.parts()]
    parts += [_box(b, ("scene", "obstacles", k), base) for k, b in enumerate(scene.obstacles)]
    parts += [_box(b, ("scene", "objects", k), base) for k, b in enumerate(scene.objects)]
    for (o, reg) in zip(params.objects, regions, strict=True):
        hit = max(((p, overlap_depth(reg, p)) for p in parts), key=lambda t: t[1], default=None)
        if hit is not None and hit[1] > TOLERANCE:
            problems.append(doc.problem(reg.loc, f"object {o.name!r} can be spawned into {hit[0].name!r}: its region, "
                                                 f"with the object's footprint, reaches {hit[1] * 1000:.1f} mm into it"))
    for (a, ra), (b, rb) in itertools.combinations(zip(params.objects, regions, strict=True), 2):
        depth = overlap_depth(ra, rb)
        if depth > TOLERANCE:
            problems.append(doc.problem(rb.loc, f"objects {b.name!r} and {a.name!r} can be spawned into each other: "
                                                f"their regions, with the objects' footprints, overlap by {depth * 1000:.1f} mm"))
    return problems


def _region_box(o: PickObject, radius: float, loc: Loc, base_dir: Path) -> _Box:
    """The box (world, axis-aligned) an object can occupy anywhere in its region, any yaw in range."""
    b = _box(o, loc, base_dir)
    half_z = float(np.sum(b.h * np.abs(b.R[2])))  # the object's half height as it is turned
    h = np.array([o.region.xy_range[0] + radius, o.region.xy_range[1] + radius, half_z])
    return _Box(o.name, loc, np.eye(3), b.c, h)
