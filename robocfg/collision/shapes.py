"""Collision models for the collision-aware IK and reactive control: the robot's URDF collision geometry as convex hulls,
plus environment shapes (obstacles, table, ground) fixed to the world (pinocchio universe joint).

Distances come from coal (through pinocchio / placo). Frames: every pose is a 4×4 homogeneous
transform in the world frame, metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

EnvKind = Literal["box", "sphere", "capsule", "cylinder", "halfspace", "convex"]


@dataclass
class EnvShape:
    """A world-fixed (or script-moved) shape the robot must keep away from.

    ``size``: box → full extents [x, y, z]; sphere → [radius]; capsule/cylinder → [radius, length]
    (axis = the shape's z); halfspace → [] (the plane z = 0 of ``pose``, free side +z);
    convex → [] and ``vertices`` (N×3, m, in the shape's frame ``pose``): their convex hull (a
    mesh or URDF body, as PyBullet collides a dynamic mesh).
    ``obstacle``: counted in the robot–obstacle clearance report (tables/ground are not).
    """

    name: str
    kind: EnvKind
    size: tuple[float, ...]
    pose: np.ndarray = field(default_factory=lambda: np.eye(4))
    obstacle: bool = True
    vertices: np.ndarray | None = None


@dataclass(frozen=True)
class LinkGeometry:
    """One URDF collision geometry of a robot link: ``kind`` box|sphere|cylinder|capsule|mesh,
    ``origin`` (4×4) in the link frame, ``size`` as in the URDF (box extents, radius, radius +
    length), ``vertices`` (N×3, m, already scaled) for meshes — used as their convex hull."""

    link: str
    kind: str
    origin: np.ndarray
    size: tuple[float, ...] = ()
    vertices: np.ndarray | None = None


def hull(vertices: np.ndarray):
    """coal convex hull of a point cloud (N×3, m)."""
    import coal

    v = np.asarray(vertices, dtype=float)
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(0, len(v))
    bvh.addVertices(v)
    bvh.endModel()
    bvh.buildConvexHull(True, "Qt")
    return bvh.convex


def link_shape(g: LinkGeometry):
    """coal geometry of a link's collision geometry (meshes as convex hulls)."""
    import coal

    if g.kind == "mesh":
        return hull(g.vertices) if g.vertices is not None and len(g.vertices) >= 4 else None
    s = g.size
    if g.kind == "box":
        return coal.Box(*map(float, s))
    if g.kind == "sphere":
        return coal.Sphere(float(s[0]))
    if g.kind == "cylinder":
        return coal.Cylinder(float(s[0]), float(s[1]))
    if g.kind == "capsule":
        return coal.Capsule(float(s[0]), float(s[1]))
    return None


def add_robot_geometry(geom_model, model, geoms: list[LinkGeometry]) -> int:
    """Attach ``geoms`` to their links' parent joints in ``geom_model`` (pinocchio ``model``); returns
    how many were added (links missing from the model and degenerate meshes are skipped)."""
    import pinocchio as pin

    n = 0
    for k, g in enumerate(geoms):
        if not model.existFrame(g.link):
            continue
        shape = link_shape(g)
        if shape is None:
            continue
        # the link's BODY frame: a joint may carry the link's name too (the Unitree Z1's gripperStator)
        body = model.existFrame(g.link, pin.FrameType.BODY)
        frame = model.frames[model.getFrameId(g.link, pin.FrameType.BODY) if body else model.getFrameId(g.link)]
        T = np.asarray(g.origin, dtype=float)
        placement = frame.placement * pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())
        geom_model.addGeometryObject(pin.GeometryObject(f"{g.link}_{k}", frame.parentJoint, placement, shape))
        n += 1
    return n


def coal_shape(shape: EnvShape):
    """The coal collision geometry for ``shape``."""
    import coal

    s = shape.size
    if shape.kind == "box":
        return coal.Box(float(s[0]), float(s[1]), float(s[2]))
    if shape.kind == "sphere":
        return coal.Sphere(float(s[0]))
    if shape.kind == "capsule":
        return coal.Capsule(float(s[0]), float(s[1]))
    if shape.kind == "cylinder":
        return coal.Cylinder(float(s[0]), float(s[1]))
    if shape.kind == "halfspace":
        return coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)
    if shape.kind == "convex":
        if shape.vertices is None or len(shape.vertices) < 4:
            raise ValueError(f"convex shape {shape.name!r} needs at least 4 vertices")
        return hull(shape.vertices)
    raise ValueError(f"unknown environment shape kind {shape.kind!r}")


def to_convex_hulls(geom_model) -> int:
    """Replace every mesh (BVH) geometry of ``geom_model`` by its convex hull, in place.

    PyBullet collides meshes as convex hulls too, so both see the same shapes; coal's
    hull-vs-primitive distance is ≈ 5× faster than mesh-vs-primitive. Returns how many were replaced.
    """
    n = 0
    for obj in geom_model.geometryObjects:
        geom = obj.geometry
        if hasattr(geom, "buildConvexHull") and type(geom).__name__.startswith("BVH"):
            geom.buildConvexHull(True, "Qt")
            obj.geometry = geom.convex
            n += 1
    return n


def add_environment(geom_model, shapes: list[EnvShape]) -> dict[str, int]:
    """Add ``shapes`` to ``geom_model`` on the universe joint; returns name → geometry id."""
    import pinocchio as pin

    ids = {}
    for shape in shapes:
        T = np.asarray(shape.pose, dtype=float)
        obj = pin.GeometryObject(f"env:{shape.name}", 0, pin.SE3(T[:3, :3].copy(), T[:3, 3].copy()), coal_shape(shape))
        ids[shape.name] = geom_model.addGeometryObject(obj)
    return ids


def set_environment_pose(geom_model, geom_id: int, pose: np.ndarray) -> None:
    """Move an environment geometry (e.g. a moving obstacle) to ``pose`` (4×4, world)."""
    import pinocchio as pin

    T = np.asarray(pose, dtype=float)
    geom_model.geometryObjects[geom_id].placement = pin.SE3(T[:3, :3].copy(), T[:3, 3].copy())


def point_clearance(geom_model, geom_ids, point: np.ndarray) -> float:
    """Distance (m) from a world point to the nearest of the geometries ``geom_ids`` (world-fixed)."""
    import coal

    probe = coal.Sphere(1e-6)
    at = coal.Transform3s(np.eye(3), np.asarray(point, dtype=float))
    best = float("inf")
    for gid in geom_ids:
        obj = geom_model.geometryObjects[gid]
        M = obj.placement
        d = coal.distance(probe, at, obj.geometry, coal.Transform3s(M.rotation, M.translation),
                          coal.DistanceRequest(), coal.DistanceResult())
        best = min(best, float(d))
    return best


def robot_geometry_ids(geom_model, fixed_joints: set[int]) -> list[int]:
    """Ids of the robot geometries that can move (parent joint not in ``fixed_joints``)."""
    return [i for i, o in enumerate(geom_model.geometryObjects)
            if o.parentJoint not in fixed_joints and not o.name.startswith("env:")]
