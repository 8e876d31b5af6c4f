"""A robot's URDF collision geometry as data: one :class:`LinkGeometry` per collision element.

Meshes are read as vertex clouds (scaled, metres, in the link frame) so the collision models
built from them (convex hulls in coal) match what PyBullet collides.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from robocfg.collision.shapes import LinkGeometry

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot


def robot_geometry(robot: CheckedRobot) -> tuple[list[LinkGeometry], list[str]]:
    """Every link's URDF collision geometry (meshes as scaled vertex clouds for convex hulls), and
    the mesh files that could not be read (their links are then not avoided)."""
    from robocfg.assets.meshes import read_vertices
    from robocfg.assets.paths import Resolver, UnresolvedPath

    resolver = Resolver(robot.path.parent, robot.config.package_dirs)
    out: list[LinkGeometry] = []
    missing: list[str] = []
    for link in robot.urdf.links.values():
        for g in link.collisions:
            if g.kind == "mesh":
                try:
                    verts = read_vertices(resolver.mesh(g.filename or "", robot.urdf_path)) * np.asarray(g.scale)
                except (UnresolvedPath, OSError, ValueError):
                    missing.append(g.filename or link.name)
                    continue
                out.append(LinkGeometry(link.name, "mesh", g.origin, (), verts))
            else:
                out.append(LinkGeometry(link.name, g.kind, g.origin, tuple(g.size)))
    return out, missing
