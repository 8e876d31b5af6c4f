"""Low-poly copies of visual meshes for the render mirror: quadric decimation (trimesh with
fast-simplification) to at most ``max_faces`` triangles, each face coloured from the textured or
coloured original, split into one untextured OBJ per colour (TinyRenderer then needs no texture
lookups). Results are cached on disk by the source file's content, so a mesh is decimated once.
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

MAX_FACES = 1000  # triangles per visual mesh in the mirror: a Panda link in a close-up still reads as itself

PALETTE = 8  # at most this many colours per decimated mesh (each becomes one untextured part)


@dataclass(frozen=True)
class Part:
    """One untextured piece of a visual mesh: an OBJ file and its colour (RGBA in 0..1)."""

    path: str
    rgba: tuple[float, ...]


def low_poly(path: str, rgba=(1.0, 1.0, 1.0, 1.0), max_faces: int = MAX_FACES) -> list[Part]:
    """``path`` (a mesh file drawn with colour ``rgba``) as at most :data:`PALETTE` untextured parts
    of at most ``max_faces`` triangles in all: the mesh is decimated (quadric decimation), each new
    face takes the colour (texture or material) of the original face under it, and faces are
    grouped by colour, so a Panda keeps its white links and black joints without its 100 000
    triangles. Cached in the temp folder by path, mtime and budget. ``[Part(path, rgba)]`` when the mesh is small
    enough or cannot be read (PyBullet then draws the original, texture and all)."""
    src = Path(path)
    whole = [Part(path, tuple(rgba))]
    if not src.is_file():
        return whole
    key = hashlib.sha1(f"{src.resolve()}:{src.stat().st_mtime_ns}:{max_faces}".encode()).hexdigest()[:16]
    folder = Path(tempfile.gettempdir()) / "robocfg_lowpoly" / f"{src.stem}_{key}"
    index = folder / "parts.json"
    if not index.is_file():
        parts = _decimate(src, max_faces, folder)
        if parts is None:
            return whole
        tmp = folder / f"parts.{os.getpid()}.tmp"
        tmp.write_text(json.dumps(parts))
        tmp.replace(index)  # atomic: parallel runs may write the same folder
    parts = json.loads(index.read_text())
    if not parts:
        return whole
    return [Part(str(folder / name), tuple(float(a) * float(b) for a, b in zip(color, rgba, strict=True)))
            for name, color in parts]


def _decimate(src: Path, max_faces: int, folder: Path) -> list[tuple[str, list[float]]] | None:
    """Write the colour groups of ``src`` decimated into ``folder``; returns [(file name, RGBA)],
    [] when the mesh is small enough to draw as it is, None when it cannot be read."""
    import trimesh

    try:
        mesh = trimesh.load(str(src), force="mesh", process=False)
    except Exception:  # a mesh trimesh cannot read: PyBullet draws the original
        return None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        return None
    folder.mkdir(parents=True, exist_ok=True)
    if len(mesh.faces) <= max_faces:
        return []
    colors = _face_colors(mesh)
    plain = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    plain.merge_vertices()  # by position only: texture seams would open holes when decimating
    small = plain.simplify_quadric_decimation(face_count=max_faces)
    from scipy.spatial import cKDTree

    _, nearest = cKDTree(mesh.triangles_center).query(small.triangles_center)
    palette, labels = _palette(colors[nearest])  # each new face takes the colour of the old one under it
    out = []
    for k, color in enumerate(palette):
        faces = np.flatnonzero(labels == k)
        if len(faces) == 0:
            continue
        part = small.submesh([faces], append=True, repair=False)
        name = f"part{k}.obj"
        tmp = folder / f"{name}.{os.getpid()}.tmp"
        tmp.write_text(trimesh.exchange.obj.export_obj(part, include_normals=True, include_texture=False,
                                                       include_color=False))
        tmp.replace(folder / name)
        out.append((name, [float(c) / 255.0 for c in color]))
    return out


def _face_colors(mesh) -> np.ndarray:
    """(F, 4) uint8 colour of each face: the texture sampled at its corners, else the material's
    diffuse colour, else white."""
    vis = mesh.visual
    if vis.kind == "texture" and getattr(vis, "uv", None) is not None and getattr(vis.material, "image", None) is not None:
        vc = np.asarray(vis.to_color().vertex_colors, float)
        return vc[mesh.faces].mean(axis=1).round().astype(np.uint8)
    material = getattr(vis, "material", None)
    main = getattr(material, "main_color", None)
    color = np.asarray(main if main is not None else (255, 255, 255, 255), dtype=np.uint8)
    return np.tile(color, (len(mesh.faces), 1))


def _palette(colors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Up to :data:`PALETTE` colours (the most common, after rounding to 16 levels a channel) and
    each face's nearest one."""
    q = (colors // 16).astype(int) * 16 + 8
    uniq, inverse, counts = np.unique(q, axis=0, return_inverse=True, return_counts=True)
    top = np.argsort(-counts)[:PALETTE]
    palette = uniq[top]
    d = ((uniq[:, None, :3] - palette[None, :, :3]) ** 2).sum(axis=2)
    labels = np.argmin(d, axis=1)[np.ravel(inverse)]
    return np.clip(palette, 0, 255), labels
