"""Vertex clouds of URDF geometries (for bounding boxes and finger-pad estimates), link frame, m.

OBJ and STL, the formats URDF meshes almost always use, are read here with numpy: `robocfg
validate` reads finger and link meshes, and importing trimesh costs that command 0.5–2 s (more
than the rest of its imports together, measured with ``python -X importtime``). Every other
format goes through trimesh.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from robocfg.assets.urdf import Geometry


def read_vertices(path: Path) -> np.ndarray:
    """(N, 3) vertices of a mesh file. OBJ and STL are read directly; other formats via trimesh."""
    suffix = path.suffix.lower()
    if suffix == ".obj":
        rows = [line.split()[1:4] for line in path.read_text(errors="replace").splitlines() if line.startswith("v ")]
        return np.asarray(rows, dtype=float).reshape(-1, 3)
    if suffix == ".stl":
        data = path.read_bytes()
        if data[:5].lower() == b"solid" and b"facet" in data[:1000]:
            rows = [ln.split()[1:4] for ln in data.decode(errors="replace").splitlines() if ln.strip().startswith("vertex")]
            return np.asarray(rows, dtype=float).reshape(-1, 3)
        (n,) = struct.unpack_from("<I", data, 80)
        tri = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]), count=n, offset=84)
        return tri["v"].reshape(-1, 3).astype(float)
    import trimesh

    loaded = trimesh.load(str(path), force="mesh", process=False)
    if not isinstance(loaded, trimesh.Trimesh):
        raise ValueError(f"{path}: not a mesh trimesh can read")
    return np.asarray(loaded.vertices, dtype=float)


def geometry_points(geom: Geometry, mesh_path: Path | None) -> np.ndarray:
    """Points bounding ``geom`` in its link frame (mesh vertices, or primitive box corners)."""
    if geom.kind == "mesh":
        if mesh_path is None:
            return np.zeros((0, 3))
        local = read_vertices(mesh_path) * np.asarray(geom.scale)
    else:
        if geom.kind == "box":
            half = np.asarray(geom.size) / 2
        elif geom.kind == "sphere":
            half = np.full(3, geom.size[0])
        else:
            r, length = geom.size
            half = np.array([r, r, length / 2 + (r if geom.kind == "capsule" else 0.0)])
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)
        local = signs * half
    return local @ geom.origin[:3, :3].T + geom.origin[:3, 3]
