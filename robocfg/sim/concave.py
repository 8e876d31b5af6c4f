"""Concave jaw meshes of one-jaw grippers, decomposed into convex parts before PyBullet loads them.

PyBullet collides with the convex hull of a mesh. For most links that is close enough; for a
gripper finger whose one mesh holds both the hand body and the jaw (Unitree Z1's fixed jaw), the
hull fills the throat between the jaws, and an object placed there is pushed out before the
moving jaw reaches it. Jaw meshes whose volume is under ``CONCAVE_RATIO`` of their hull's are
decomposed with PyBullet's V-HACD into an OBJ of convex parts (one ``o`` group each, which
PyBullet loads as a compound of hulls). The result is cached in the temp folder by the mesh
file's content, so the few seconds V-HACD takes are paid once per mesh.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import pybullet as p

from robocfg.sim.quiet import captured_stdout

CONCAVE_RATIO = 0.8  # mesh volume / convex-hull volume below which a finger mesh is decomposed
VHACD_RESOLUTION = 100_000  # V-HACD voxels (its default)


def convex_parts(mesh: Path, scale: tuple[float, float, float] = (1.0, 1.0, 1.0)) -> Path | None:
    """An OBJ of convex parts for ``mesh`` when it is markedly concave, else None (the mesh is
    loaded as it is). The volume of a mesh that is not quite closed is trimesh's estimate; a mesh
    without volume (a surface) is left alone."""
    import trimesh

    try:
        m = trimesh.load(str(mesh), force="mesh")
    except (ValueError, OSError):
        return None
    if not isinstance(m, trimesh.Trimesh) or abs(m.volume) <= 0 or m.convex_hull.volume <= 0:
        return None
    if abs(m.volume) / m.convex_hull.volume >= CONCAVE_RATIO:
        return None
    digest = hashlib.sha1(mesh.read_bytes() + repr(scale).encode()).hexdigest()[:16]
    folder = Path(tempfile.gettempdir()) / "robocfg_vhacd"
    out = folder / f"{mesh.stem}_{digest}.obj"
    if out.exists():
        return out
    folder.mkdir(parents=True, exist_ok=True)
    src = folder / f"{mesh.stem}_{digest}.{os.getpid()}.in.obj"
    tmp = folder / f"{mesh.stem}_{digest}.{os.getpid()}.obj"
    m.export(str(src))
    client = p.connect(p.DIRECT)
    try:
        with captured_stdout():
            p.vhacd(str(src), str(tmp), str(folder / f"{digest}.log"), resolution=VHACD_RESOLUTION, physicsClientId=client)
    finally:
        p.disconnect(client)
        src.unlink(missing_ok=True)
    if not tmp.exists() or tmp.stat().st_size == 0:
        return None
    tmp.replace(out)
    return out
