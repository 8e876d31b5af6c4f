"""The real geometry of a task body: its collision shape as convex pieces, in the body frame.

Every shape a task can name is turned into one description, so the checks and the grasp choice
never read ``size`` by hand (for a mesh ``size`` is a *scale*, not extents):

* box, sphere, cylinder, capsule: the primitive PyBullet builds (cylinder and capsule along the
  body's z axis, ``length`` between the cap centres for a capsule);
* a mesh file (OBJ, STL, anything trimesh reads): scaled by ``size``; each connected part becomes
  its convex hull, as PyBullet collides with a dynamic mesh body;
* a URDF object (``pybullet_data://duck_vhacd.urdf``, ``random_urdfs/000/000.urdf``): the root
  link's collision geometry, scaled by ``size[0]`` (PyBullet's ``globalScaling``), and the
  link's ``<inertial>`` mass.

Frame: the body frame PyBullet reports for the body (``getBasePositionAndOrientation``), which for
a URDF is the root link's *inertial* frame, not its link frame; lengths in metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np

from robocfg.assets.mesh_part import MeshPart
from robocfg.assets.paths import body_asset
from robocfg.assets.urdf import Geometry
from robocfg.assets.urdf_xml import parse_urdf, read_urdf_xml
from robocfg.config.scene import Body
from robocfg.geometry import rpy_matrix

if TYPE_CHECKING:
    import trimesh

FINGER_CLEARANCE = 0.004  # m: free gap left on each side of an object between open fingers
SECTIONS = 16  # facets of a cylinder/capsule/sphere approximation (points on hulls, not for physics)


@dataclass(frozen=True)
class ObjectShape:
    """A body's collision geometry: ``parts`` convex meshes in the body frame (m);
    ``file_mass``: the URDF's root-link mass (kg), None for primitives and bare mesh files;
    ``symmetry``: "spherical" (a sphere: every orientation alike), "axial" (cylinder, capsule:
    turns about the body's z axis alike) or "none"."""

    parts: tuple[MeshPart, ...]
    file_mass: float | None = None
    symmetry: Literal["none", "axial", "spherical"] = "none"

    def tilt_deg(self, R_start: np.ndarray, R_now: np.ndarray) -> float:
        """How far (deg) the body has tipped from how it lay at ``R_start``, turns that leave its
        shape as it was not counted: yaw about the vertical, a ball's roll, a cylinder's roll
        about its own axis (then only the axis' change of slope counts)."""
        if self.symmetry == "spherical":
            return 0.0
        if self.symmetry == "axial":
            slope = [math.asin(min(1.0, abs(float(R[2, 2])))) for R in (R_start, R_now)]
            return math.degrees(abs(slope[1] - slope[0]))
        up = float(np.asarray(R_now)[2] @ np.asarray(R_start)[2])
        return math.degrees(math.acos(max(-1.0, min(1.0, up))))

    @property
    def vertices(self) -> np.ndarray:
        """(N, 3) hull vertices of every part, body frame (m); gathered once per shape (read-only:
        every pose of the object reads them)."""
        v = self.__dict__.get("_vertices")
        if v is None:
            v = np.concatenate([np.asarray(p.vertices) for p in self.parts])
            v.setflags(write=False)
            self.__dict__["_vertices"] = v
        return v

    def extents(self) -> np.ndarray:
        """Axis-aligned extents (m) in the body frame."""
        v = self.vertices
        return v.max(axis=0) - v.min(axis=0)

    def posed(self, R: np.ndarray) -> np.ndarray:
        """Hull vertices rotated by the body orientation ``R`` (3x3), relative to the body origin."""
        return self.vertices @ np.asarray(R, float).T

    def below_origin(self, R: np.ndarray) -> float:
        """How far (m) the lowest point lies below the body origin when the body is turned by ``R``:
        the origin's height above a support it rests on."""
        return float(-self.posed(R)[:, 2].min())

    def height(self, R: np.ndarray) -> float:
        """Vertical extent (m) when turned by ``R``."""
        z = self.posed(R)[:, 2]
        return float(z.max() - z.min())

    def min_horizontal_width(self, R: np.ndarray, directions: int = 180) -> float:
        """The narrowest horizontal width (m) of the body turned by ``R``, over ``directions``
        directions in half a turn: the least a parallel gripper closing horizontally must span."""
        xy = self.posed(R)[:, :2]
        a = np.linspace(0.0, np.pi, directions, endpoint=False)
        proj = xy @ np.stack([np.cos(a), np.sin(a)])
        return float((proj.max(axis=0) - proj.min(axis=0)).min())

    def top_at(self, R: np.ndarray, position, x: float, y: float) -> float | None:
        """Height (m, world) of the body's top surface above the point (x, y) when it stands at
        ``position`` turned by ``R``; None when no part of it is above or below that point. Exact
        for the convex parts: the vertical line is clipped by every face plane."""
        best = None
        for part in self.parts:
            n = np.asarray(part.face_normals) @ np.asarray(R, float).T
            v = np.asarray(part.triangles[:, 0]) @ np.asarray(R, float).T + np.asarray(position, float)
            rhs = np.einsum("ij,ij->i", n, v) - n[:, 0] * x - n[:, 1] * y  # n_z z <= rhs on every face
            up, down, side = n[:, 2] > 1e-9, n[:, 2] < -1e-9, np.abs(n[:, 2]) <= 1e-9
            if np.any(rhs[side] < -1e-9) or not np.any(up):
                continue
            top = float(np.min(rhs[up] / n[up, 2]))
            bottom = float(np.max(rhs[down] / n[down, 2])) if np.any(down) else -np.inf
            if bottom <= top + 1e-9:
                best = top if best is None else max(best, top)
        return best

    def fixed_surface(self, count: int) -> np.ndarray:
        """``surface(count, default_rng(0))``'s points (body frame, m), drawn once per shape and
        count: the same fixed sample every time it is asked for (read-only)."""
        cache: dict[int, np.ndarray] = self.__dict__.setdefault("_fixed_surface", {})
        if count not in cache:
            pts = self.surface(count, np.random.default_rng(0))[0]
            pts.setflags(write=False)
            cache[count] = pts
        return cache[count]

    def surface(self, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``count`` points spread over the parts' surfaces (area-weighted) and their outward unit
        normals, body frame: the object's own point cloud, no camera needed."""
        areas = np.array([p.area for p in self.parts])
        picks = rng.choice(len(self.parts), size=count, p=areas / areas.sum())
        pts, nrm = [], []
        for k, part in enumerate(self.parts):
            n = int((picks == k).sum())
            if not n:
                continue
            tri = rng.choice(len(part.faces), size=n, p=part.area_faces / part.area)
            u, v = rng.random(n), rng.random(n)
            flip = u + v > 1
            u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
            corners = part.triangles[tri]
            pts.append(corners[:, 0] + u[:, None] * (corners[:, 1] - corners[:, 0]) + v[:, None] * (corners[:, 2] - corners[:, 0]))
            nrm.append(part.face_normals[tri])
        return np.concatenate(pts), np.concatenate(nrm)


def object_shape(body: Body, base_dir: Path) -> ObjectShape:
    """The geometry of ``body`` (a task's object or obstacle); ``base_dir`` resolves relative mesh
    paths (the task file's folder). Raises UnresolvedPath for a missing file, ValueError for a
    file that holds no usable geometry."""
    s = [float(v) for v in body.size]
    if body.shape == "box":  # no trimesh: the common case stays off its 0.3-1.5 s import
        return ObjectShape((MeshPart.box(s),))
    import trimesh

    if body.shape == "sphere":
        return _shape((trimesh.creation.icosphere(subdivisions=2, radius=s[0]),), symmetry="spherical")
    if body.shape == "cylinder":
        return _shape((trimesh.creation.cylinder(radius=s[0], height=s[1], sections=SECTIONS),), symmetry="axial")
    if body.shape == "capsule":
        return _shape((trimesh.creation.capsule(height=s[1], radius=s[0], count=[SECTIONS, SECTIONS]),),
                      symmetry="axial")
    path = body_asset(body.mesh or "", base_dir)
    if path.suffix.lower() == ".urdf":
        return _urdf_shape(path, s[0])
    return _shape(_hulls(path, tuple(s)))


def _shape(parts: tuple[trimesh.Trimesh, ...], file_mass: float | None = None,
           symmetry: Literal["none", "axial", "spherical"] = "none") -> ObjectShape:
    return ObjectShape(tuple(MeshPart.of(p) for p in parts), file_mass, symmetry)


@lru_cache(maxsize=64)
def _hulls(path: Path, scale: tuple[float, float, float]) -> tuple[trimesh.Trimesh, ...]:
    """Convex hull of each connected part of the mesh file, scaled (a VHACD file's parts are its
    convex pieces; a single-part mesh collides as its hull in PyBullet)."""
    import trimesh

    mesh = trimesh.load(str(path), force="mesh", process=False)
    if not isinstance(mesh, trimesh.Trimesh) or not len(mesh.vertices):
        raise ValueError(f"{path}: no mesh that trimesh can read")
    mesh = mesh.copy()
    mesh.apply_scale(np.asarray(scale, float))
    mesh.merge_vertices()
    parts = [p for p in mesh.split(only_watertight=False) if len(p.vertices) >= 4] or [mesh]
    return tuple(_hull(p) for p in parts)


def _hull(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    import trimesh

    try:
        return mesh.convex_hull
    except Exception:  # flat or degenerate part (qhull refuses): keep its bounding box
        return trimesh.creation.box(bounds=mesh.bounds + np.array([[-1e-4] * 3, [1e-4] * 3]))


def _urdf_shape(path: Path, scaling: float) -> ObjectShape:
    urdf = parse_urdf(path)
    link = urdf.links[urdf.root]
    parts: list[trimesh.Trimesh] = []
    for geom in link.collisions:
        for part in _geometry_parts(geom, path):
            T = geom.origin.copy()
            part = part.copy()
            part.apply_transform(T)
            parts.append(part)
    if not parts:
        raise ValueError(f"{path}: root link {link.name!r} has no collision geometry")
    com = _inertial_origin(path)
    out = []
    for part in parts:
        part = part.copy()
        part.apply_transform(np.linalg.inv(com))  # into the inertial frame PyBullet reports
        part.apply_scale(scaling)
        out.append(part)
    return _shape(tuple(out), link.mass)


def _geometry_parts(geom: Geometry, urdf_path: Path) -> tuple[trimesh.Trimesh, ...]:
    import trimesh

    if geom.kind == "mesh":
        mesh_path = (urdf_path.parent / (geom.filename or "")).resolve()
        return _hulls(mesh_path, tuple(float(v) for v in geom.scale))
    if geom.kind == "box":
        return (trimesh.creation.box(extents=list(geom.size)),)
    if geom.kind == "sphere":
        return (trimesh.creation.icosphere(subdivisions=2, radius=geom.size[0]),)
    r, length = geom.size
    if geom.kind == "capsule":
        return (trimesh.creation.capsule(height=length, radius=r, count=[SECTIONS, SECTIONS]),)
    return (trimesh.creation.cylinder(radius=r, height=length, sections=SECTIONS),)


def _inertial_origin(path: Path) -> np.ndarray:
    """link_T_inertial (4x4) of the root link (identity when the URDF gives none)."""
    root = read_urdf_xml(path)
    urdf = parse_urdf(path)
    T = np.eye(4)
    for el in root.iter("link"):
        if el.get("name") != urdf.root:
            continue
        origin = el.find("inertial/origin")
        if origin is not None:
            T[:3, 3] = [float(v) for v in (origin.get("xyz") or "0 0 0").split()]
            T[:3, :3] = rpy_matrix(*[float(v) for v in (origin.get("rpy") or "0 0 0").split()])
    return T
