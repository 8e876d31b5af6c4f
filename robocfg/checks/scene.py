"""Scene checks made before simulating: names, fixtures overlapping each other, objects and
obstacles spawned inside a fixture's part.

Every shape is tested as its oriented bounding box (spheres and cylinders as the box around them,
meshes as their scale box), with the separating-axis test; overlaps deeper than ``TOLERANCE`` are
errors located at the offending entry (``scene.objects[2].position``), naming both bodies.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robocfg.config.load import Loc, YamlDocument
from robocfg.config.scene import Body, Scene
from robocfg.errors import Problem

TOLERANCE = 0.001  # m: resting contact (a cube on a bin floor) is not an overlap


@dataclass(frozen=True)
class _Box:
    name: str
    loc: Loc
    R: np.ndarray  # world_R_box
    c: np.ndarray  # centre (m, world)
    h: np.ndarray  # half extents (m)


def _half_extents(b: Body) -> np.ndarray:
    s = b.size
    if b.shape in ("box", "mesh"):
        return np.asarray(s, float) / 2
    if b.shape == "sphere":
        return np.full(3, s[0])
    return np.array([s[0], s[0], s[1] / 2 + (s[0] if b.shape == "capsule" else 0.0)])


def _box(b: Body, loc: tuple, base_dir: Path | None = None) -> _Box:
    """The body's bounding box in the world. A body turned by ``euler_deg`` (or not at all) uses
    the closed-form roll-pitch-yaw matrix: importing scipy's ``Rotation`` would be most of the
    time ``validate`` takes to reject a task; quaternions go through it. A mesh or URDF body
    (``size`` is its scale, not its extents) gets the box of its collision geometry
    (:func:`robocfg.assets.object_shape.object_shape`, relative paths from ``base_dir``) about
    that geometry's centre; a mesh that cannot be read keeps the scale box (the asset checks
    report the file)."""
    from robocfg.geometry import quat_to_matrix, rpy_matrix

    if b.quat_xyzw is None and b.quat_wxyz is None:
        R = rpy_matrix(*np.radians(b.euler_deg or [0.0, 0.0, 0.0]))
    else:
        R = quat_to_matrix(b.quaternion_xyzw())
    c = np.asarray(b.position, dtype=float)
    if b.shape == "mesh":
        from robocfg.assets.object_shape import object_shape
        from robocfg.assets.paths import UnresolvedPath

        try:
            v = object_shape(b, base_dir or Path(".")).vertices
        except (UnresolvedPath, OSError, ValueError):
            return _Box(b.name, loc, R, c, _half_extents(b))
        lo, hi = v.min(axis=0), v.max(axis=0)
        return _Box(b.name, loc, R, c + R @ ((lo + hi) / 2), (hi - lo) / 2)
    return _Box(b.name, loc, R, c, _half_extents(b))


def overlap_depth(a: _Box, b: _Box) -> float:
    """Smallest overlap (m) along the 15 separating-axis candidates; ≤ 0 if the boxes are apart."""
    axes = [a.R[:, i] for i in range(3)] + [b.R[:, i] for i in range(3)]
    axes += [np.cross(a.R[:, i], b.R[:, j]) for i in range(3) for j in range(3)]
    d = b.c - a.c
    depth = np.inf
    for ax in axes:
        n = float(np.linalg.norm(ax))
        if n < 1e-9:  # parallel edges: already covered by the face axes
            continue
        ax = ax / n
        ra = float(np.sum(a.h * np.abs(a.R.T @ ax)))
        rb = float(np.sum(b.h * np.abs(b.R.T @ ax)))
        depth = min(depth, ra + rb - abs(float(d @ ax)))
    return depth


def check_scene(doc: YamlDocument, scene: Scene, extra: Sequence[tuple[Loc, Body]] = ()) -> list[Problem]:
    """Problems of ``scene`` (and of ``extra`` (location, body) pairs such as a task's object)."""
    problems: list[Problem] = []
    names: dict[str, Loc] = {}
    movable = [(("scene", "objects", k), b) for k, b in enumerate(scene.objects)] + list(extra)
    for loc, b in [*movable, *((("scene", "obstacles", k), b) for k, b in enumerate(scene.obstacles))]:
        names.setdefault(b.name, loc)
    for k, f in enumerate(scene.fixtures):
        loc = ("scene", "fixtures", k, "name")
        if f.name in names or "/" in f.name:
            why = "contains '/'" if "/" in f.name else f"is already used at {'.'.join(map(str, names[f.name]))}"
            problems.append(doc.problem(loc, f"fixture name {f.name!r} {why}"))
        names.setdefault(f.name, loc)
    parts = [[_box(p, ("scene", "fixtures", k, "position")) for p in f.parts()] for k, f in enumerate(scene.fixtures)]
    for fa, fb in itertools.combinations(parts, 2):
        overlap = _deepest(fa, fb)
        if overlap is not None:
            pa, pb, depth = overlap
            problems.append(doc.problem(pb.loc, f"fixture part {pb.name!r} overlaps fixture part {pa.name!r} by {depth * 1000:.1f} mm"))
    fixture_boxes = [p for ps in parts for p in ps]
    things = [(loc, b, "object") for loc, b in movable] + \
             [(("scene", "obstacles", k), b, "obstacle") for k, b in enumerate(scene.obstacles)]
    for loc, body, what in things:
        inside = _deepest([_box(body, (*loc, "position"), doc.path.parent)], fixture_boxes)
        if inside is not None:
            box, part, depth = inside
            problems.append(doc.problem(box.loc, f"{what} {body.name!r} is inside fixture part {part.name!r} "
                                               f"(overlap {depth * 1000:.1f} mm)"))
    return problems


def _deepest(xs: list[_Box], ys: list[_Box]) -> tuple[_Box, _Box, float] | None:
    best = None
    for a in xs:
        for b in ys:
            d = overlap_depth(a, b)
            if d > TOLERANCE and (best is None or d > best[2]):
                best = (a, b, d)
    return best
