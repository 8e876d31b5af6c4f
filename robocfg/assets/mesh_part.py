"""One convex piece of a body's collision geometry as plain arrays, without trimesh.

:class:`MeshPart` holds what :class:`robocfg.assets.object_shape.ObjectShape` reads from a piece
(vertices, triangle faces, outward face normals; triangles and face areas computed from them by
the same formulas as trimesh, so the numbers are the same bits). A box is built here directly
from trimesh's own box table; other shapes are made with trimesh and converted, so only the tasks
whose objects need it pay ``import trimesh`` (0.3–1.5 s with scipy.spatial, networkx and
scipy.optimize that it pulls in) — ``robocfg validate`` and a pick-place of a cube do not.

Frame: whatever frame the vertices are given in (the body frame for an object shape); metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import trimesh

# trimesh.creation.box's unit cube (trimesh 4–5 ``resources/templates/box``): the same vertex and
# face order, so a box's faces, normals and surface samples are the ones trimesh gives
_BOX_VERTICES = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]],
                         dtype=np.float64)
_BOX_FACES = np.array([[1, 3, 0], [4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4], [5, 7, 1], [3, 7, 2],
                       [6, 4, 2], [2, 7, 6], [6, 5, 4], [7, 5, 6]], dtype=np.int64)
_BOX_NORMALS = np.array([[-1, 0, 0], [0, -1, 0], [-1, 0, 0], [0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 0, 1], [0, 1, 0],
                         [0, 0, -1], [0, 1, 0], [1, 0, 0], [1, 0, 0]], dtype=np.float64)


@dataclass(frozen=True, eq=False)
class MeshPart:
    """A triangle mesh: ``vertices`` (N, 3) in m, ``faces`` (M, 3) vertex indices (counter-clockwise
    seen from outside), ``face_normals`` (M, 3) outward unit normals. Arrays are read-only."""

    vertices: np.ndarray
    faces: np.ndarray
    face_normals: np.ndarray

    def __post_init__(self) -> None:
        for a in (self.vertices, self.faces, self.face_normals):
            a.setflags(write=False)

    @classmethod
    def box(cls, extents) -> MeshPart:
        """A box of ``extents`` (3,) m centred on the origin: ``trimesh.creation.box(extents=...)``'s
        vertices, faces and normals."""
        v = _BOX_VERTICES.copy()
        v -= 0.5
        v *= np.asarray(extents, dtype=np.float64)
        return cls(v, _BOX_FACES.copy(), _BOX_NORMALS.copy())

    @classmethod
    def of(cls, mesh: trimesh.Trimesh) -> MeshPart:
        """The arrays of a trimesh mesh (copied)."""
        return cls(np.array(mesh.vertices, dtype=np.float64), np.array(mesh.faces, dtype=np.int64),
                   np.array(mesh.face_normals, dtype=np.float64))

    @cached_property
    def triangles(self) -> np.ndarray:
        """(M, 3, 3) corner points of every face (m)."""
        return self.vertices[self.faces]

    @cached_property
    def area_faces(self) -> np.ndarray:
        """(M,) area of every face (m²), as trimesh computes it (half the edge cross product's norm)."""
        tri = self.triangles
        vectors = tri[:, 1:, :] - tri[:, :2, :]
        crosses = np.cross(vectors[:, 0], vectors[:, 1])
        return np.sqrt((crosses**2).sum(axis=1)) / 2.0

    @cached_property
    def area(self) -> float:
        """Surface area (m²)."""
        return float(self.area_faces.sum())
