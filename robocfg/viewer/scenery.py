"""A task YAML's scene in the browser viewer: table, pedestal, objects, obstacles, and for a
pick-place task the object and a disc at the place target. Primitive shapes are built with trimesh
in each body's own frame, then posed in the world (m); a ``mesh`` body is loaded with trimesh."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import trimesh

from robocfg.checks import CheckedTask
from robocfg.config.scene import Body
from robocfg.geometry.pose import pose_matrix

if TYPE_CHECKING:
    import viser

PLACE_COLOR = (40, 200, 60, 110)


def body_mesh(body: Body, base_dir) -> trimesh.Trimesh | None:
    """A trimesh of ``body`` in its own frame (None if a mesh file cannot be read)."""
    s = body.size
    if body.shape == "box":
        return trimesh.creation.box(extents=s)
    if body.shape == "sphere":
        return trimesh.creation.icosphere(radius=s[0], subdivisions=3)
    if body.shape == "cylinder":
        return trimesh.creation.cylinder(radius=s[0], height=s[1])
    if body.shape == "capsule":
        return trimesh.creation.capsule(radius=s[0], height=s[1])
    from robocfg.sim.bodies import resolve_asset

    try:
        loaded = trimesh.load(resolve_asset(body.mesh or "", base_dir), force="mesh")
    except (OSError, ValueError):
        return None
    if not isinstance(loaded, trimesh.Trimesh):  # force="mesh" gives one; anything else is unreadable
        return None
    loaded.apply_scale(s)
    return loaded


def _colored(mesh: trimesh.Trimesh, rgba) -> trimesh.Trimesh:
    """``mesh`` in the colour ``rgba`` (0..1 or 0..255); a textured mesh keeps its texture."""
    c = np.asarray(rgba, float)
    if isinstance(mesh.visual, trimesh.visual.ColorVisuals):
        mesh.visual.face_colors = np.clip(np.round(c if c.max() > 1 else c * 255), 0, 255).astype(np.uint8)
    return mesh


def add_scenery(server: viser.ViserServer, task: CheckedTask) -> dict[str, viser.GlbHandle]:
    """Add the task's bodies to ``server``'s scene; returns the scene handles by body name (a
    body's mesh is in its own frame and the handle carries its pose, so a playback can move it)."""
    from robocfg.geometry.rotation import matrix_to_quat

    cfg, base = task.config, task.path.parent
    items: list[tuple[str, trimesh.Trimesh, np.ndarray]] = []
    scene = cfg.scene
    if scene.table is not None:
        t = scene.table
        T = pose_matrix(t)
        T[:3, 3] -= T[:3, 2] * t.size[2] / 2  # position is the top face
        items.append(("table", _colored(trimesh.creation.box(extents=t.size), t.color), T))
    if scene.pedestal is not None:
        pd = scene.pedestal
        T = pose_matrix(pd)
        T[:3, 3] -= T[:3, 2] * pd.height / 2
        items.append(("pedestal", _colored(trimesh.creation.cylinder(radius=pd.radius, height=pd.height), pd.color), T))
    bodies = [*scene.obstacles, *scene.objects]
    params = getattr(cfg, "pick_place", None)
    if params is not None:
        bodies.append(params.object)
        disc = trimesh.creation.cylinder(radius=0.05, height=0.004)
        T = np.eye(4)
        T[:3, 3] = [params.place_position[0], params.place_position[1], 0.002]
        items.append(("place_target", _colored(disc, PLACE_COLOR), T))
    for b in bodies:
        mesh = body_mesh(b, base)
        if mesh is not None:
            items.append((b.name, _colored(mesh, b.color), pose_matrix(b)))
    handles: dict[str, viser.GlbHandle] = {}
    for name, mesh, T in items:
        x, y, z, w = matrix_to_quat(T[:3, :3])
        handles[name] = server.scene.add_mesh_trimesh(f"/scene/{name}", mesh, position=(float(T[0, 3]), float(T[1, 3]), float(T[2, 3])),
                                                      wxyz=(float(w), float(x), float(y), float(z)))
    return handles
