"""Scene bodies from task YAML models: primitives, meshes, table, pedestal, ground. SI units.

A Body's ``position`` is its centre (centre of mass for primitives); a Table's and a Pedestal's
``position`` is the centre of their top face.
"""

from __future__ import annotations

from pathlib import Path

import pybullet as p
import pybullet_data

from robocfg.assets.paths import UnresolvedPath, body_asset
from robocfg.config.scene import Body, Pedestal, Table
from robocfg.errors import NotFound, RobocfgError

LEG_SIZE = 0.05  # m: square table legs


def _shapes(client: int, body: Body, base_dir: Path) -> tuple[int, int]:
    s, rgba = body.size, list(body.color)
    if body.shape == "box":
        half = [v / 2 for v in s]
        return (p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client),
                p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client))
    if body.shape == "sphere":
        return (p.createCollisionShape(p.GEOM_SPHERE, radius=s[0], physicsClientId=client),
                p.createVisualShape(p.GEOM_SPHERE, radius=s[0], rgbaColor=rgba, physicsClientId=client))
    if body.shape in ("cylinder", "capsule"):
        kind = p.GEOM_CYLINDER if body.shape == "cylinder" else p.GEOM_CAPSULE
        return (p.createCollisionShape(kind, radius=s[0], height=s[1], physicsClientId=client),
                p.createVisualShape(kind, radius=s[0], length=s[1], rgbaColor=rgba, physicsClientId=client))
    path = str(resolve_asset(body.mesh or "", base_dir))
    col = p.createCollisionShape(p.GEOM_MESH, fileName=path, meshScale=list(s), physicsClientId=client)
    vis = p.createVisualShape(p.GEOM_MESH, fileName=path, meshScale=list(s), rgbaColor=rgba, physicsClientId=client)
    return col, vis


class ShapeCache:
    """The collision and visual shapes one physics client already holds, by (shape, size, mesh file,
    colour), so that a body spawned again (the object of every episode) reuses its shapes.

    PyBullet never frees what ``createCollisionShape`` / ``createVisualShape`` made: ``removeBody``
    leaves the shapes behind and ``removeCollisionShape`` refuses a shape a removed body used. A
    shape made per spawn grew a long run by ≈ 4.7 KiB per episode for a box (a mesh: its hull).
    One cache per world: shape ids mean nothing in another client (ids are reused after a
    disconnect)."""

    def __init__(self) -> None:
        self._ids: dict[tuple[str, tuple[float, ...], str, tuple[float, ...]], tuple[int, int]] = {}

    def __len__(self) -> int:
        return len(self._ids)

    def shapes(self, client: int, body: Body, base_dir: Path) -> tuple[int, int]:
        """(collision shape id, visual shape id) of ``body``'s primitive or mesh file."""
        mesh = str(resolve_asset(body.mesh or "", base_dir)) if body.shape == "mesh" else ""
        key = (body.shape, tuple(body.size), mesh, tuple(body.color))
        ids = self._ids.get(key)
        if ids is None:
            ids = _shapes(client, body, base_dir)
            if ids[0] >= 0:
                self._ids[key] = ids
        return ids


def resolve_asset(uri: str, base_dir: Path) -> Path:
    """A mesh/URDF path: ``pybullet_data://REL``, absolute, or relative to the task file's folder."""
    try:
        return body_asset(uri, base_dir)
    except UnresolvedPath as exc:
        raise NotFound("mesh file", uri, [str(t) for t in exc.tried]) from None


def spawn_body(client: int, body: Body, base_dir: Path, static: bool = False, cache: ShapeCache | None = None) -> int:
    """Create ``body`` (primitive, mesh file, or a ``.urdf`` scaled by ``size[0]``); returns its id.
    ``cache``: the client's shapes to reuse (a body spawned again and again: see :class:`ShapeCache`)."""
    mass = 0.0 if static else body.mass
    quat = body.quaternion_xyzw()
    if body.shape == "mesh" and (body.mesh or "").endswith(".urdf"):
        path = resolve_asset(body.mesh or "", base_dir)
        bid = p.loadURDF(str(path), body.position, quat, useFixedBase=static or mass == 0,
                         globalScaling=body.size[0], physicsClientId=client)
        if mass > 0:
            p.changeDynamics(bid, -1, mass=mass, physicsClientId=client)
        p.changeVisualShape(bid, -1, rgbaColor=list(body.color), physicsClientId=client)
    else:
        col, vis = cache.shapes(client, body, base_dir) if cache is not None else _shapes(client, body, base_dir)
        if col < 0:
            raise RobocfgError(f"PyBullet cannot load the shape of body {body.name!r} ({body.mesh or body.shape})")
        bid = p.createMultiBody(mass, col, vis, body.position, quat, physicsClientId=client)
    p.changeDynamics(bid, -1, lateralFriction=body.friction, physicsClientId=client)
    return bid


def spawn_ground(client: int, visuals: bool = True) -> int:
    """pybullet_data's plane.urdf at z = 0 (``visuals=False``: without its textured mesh, for a
    world nothing draws; the collision box is the same)."""
    return p.loadURDF(str(Path(pybullet_data.getDataPath()) / "plane.urdf"), useFixedBase=True,
                      flags=0 if visuals else p.URDF_IGNORE_VISUAL_SHAPES, physicsClientId=client)


def spawn_table(client: int, table: Table) -> list[int]:
    """Static table: the top slab (first id) and, if it stands above the ground, four legs."""
    sx, sy, sz = table.size
    top = Body(name="table", shape="box", size=[sx, sy, sz], mass=0.0, friction=table.friction,
               color=list(table.color), position=[table.position[0], table.position[1], table.position[2] - sz / 2],
               quat_xyzw=list(table.quaternion_xyzw()))
    ids = [spawn_body(client, top, Path("."), static=True)]
    leg_h = table.position[2] - sz
    if leg_h > 0.01:
        from robocfg.geometry import quat_to_matrix

        R = quat_to_matrix(table.quaternion_xyzw())
        for dx in (-1, 1):
            for dy in (-1, 1):
                off = R @ [dx * (sx / 2 - LEG_SIZE), dy * (sy / 2 - LEG_SIZE), 0.0]
                leg = Body(name="table_leg", shape="box", size=[LEG_SIZE, LEG_SIZE, leg_h], mass=0.0,
                           color=list(table.color), quat_xyzw=list(table.quaternion_xyzw()),
                           position=[table.position[0] + off[0], table.position[1] + off[1], leg_h / 2])
                ids.append(spawn_body(client, leg, Path("."), static=True))
    return ids


def spawn_pedestal(client: int, ped: Pedestal) -> int:
    """Static cylinder whose top face is centred at ``ped.position``."""
    body = Body(name="pedestal", shape="cylinder", size=[ped.radius, ped.height], mass=0.0, color=list(ped.color),
                position=[ped.position[0], ped.position[1], ped.position[2] - ped.height / 2],
                quat_xyzw=list(ped.quaternion_xyzw()))
    return spawn_body(client, body, Path("."), static=True)
