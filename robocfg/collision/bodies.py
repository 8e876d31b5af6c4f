"""Collision shapes of a task's bodies (objects, obstacles) for the planner and the grasp filter.

A primitive body (box, sphere, cylinder, capsule) becomes the same primitive; a mesh or URDF body
(``shape: mesh``) becomes the convex hull of its collision geometry
(:func:`robocfg.assets.object_shape.object_shape`: each convex part as PyBullet collides it; the
hull of all parts is one convex shape that holds them, so it can only be larger than the body).

Frames: the shape's vertices are in the body frame PyBullet reports for the body
(``getBasePositionAndOrientation``: for a URDF the root link's inertial frame), so a pose read
from the simulation (``World.body_pose``) places the hull where the body is. Metres.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.collision.shapes import EnvShape

if TYPE_CHECKING:
    from robocfg.config.scene import Body


def body_vertices(body: Body, base_dir: Path) -> np.ndarray:
    """Vertices (N×3, m, body frame) of ``body``'s convex collision parts; ``base_dir`` resolves a
    relative mesh path (the task file's folder)."""
    from robocfg.assets.object_shape import object_shape

    return np.asarray(object_shape(body, base_dir).vertices, float)


def body_env_shape(body: Body, pose: np.ndarray, base_dir: Path, obstacle: bool = True) -> EnvShape:
    """The collision shape of ``body`` at ``pose`` (4×4, world, or in a link's frame for a held
    body): its primitive, or for ``shape: mesh`` the convex hull of its collision geometry."""
    T = np.asarray(pose, float)
    if body.shape == "mesh":
        return EnvShape(body.name, "convex", (), T, obstacle, vertices=body_vertices(body, base_dir))
    return EnvShape(body.name, body.shape, tuple(body.size), T, obstacle)
