"""From the world to clouds: render every camera, fuse, crop to the workspace, downsample, split
into object points (segmentation: bodies that are not the robot, the ground or the table) and
scene points (everything but the robot, for collision checks), normals on the object points."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robocfg.config.commands import GraspParams
from robocfg.grasp.cloud import Cloud, crop, estimate_normals, from_rgbd, voxel_downsample
from robocfg.sim.camera import capture, look_direction, sees_box

COLLISION_VOXEL = 0.006  # m: leaf of the (coarser) scene cloud used for collision checks


@dataclass
class Perception:
    """``objects``: points with normals of the target (the object with the most points in the
    workspace, by segmentation); ``scene``: (M, 3) points of every body that is not
    the robot or the support (collision checks); ``support_z``: height (m) of the support under
    the objects, the median of the support points (None if none seen); ``raw_points``: points in
    the workspace before downsampling; ``captures``: the RGB-D images."""

    objects: Cloud
    scene: np.ndarray
    support_z: float | None
    raw_points: int
    captures: list


def cameras(params: GraspParams) -> list:
    return [params.camera, *params.extra_cameras]


def camera_warnings(params: GraspParams) -> list[str]:
    """One warning per camera whose view does not contain the workspace centre, or that looks up."""
    ws = params.workspace
    out = []
    for k, cam in enumerate(cameras(params)):
        name = "camera" if k == 0 else f"extra_cameras[{k - 1}]"
        if look_direction(cam)[2] >= 0:
            out.append(f"grasp.{name} looks level or upwards (look_at {cam.look_at} from {cam.position}): "
                       "it cannot see the table")
        elif not sees_box(cam, ws.min, ws.max):
            out.append(f"grasp.{name} looks away from the table: the workspace centre is outside its view")
    return out


def perceive(world, params: GraspParams, rng: np.random.Generator) -> Perception:
    """Render, fuse and process the clouds of the world's current state."""
    robot_ids = {r.body_id for r in world.robots}
    background = {world.bodies[n] for n in world.bodies if n == "ground" or n.startswith("table")}
    caps = [capture(world.client, cam, rng) for cam in cameras(params)]
    fused = Cloud.concat([from_rgbd(c) for c in caps])
    fused = fused.select(~np.isin(fused.labels, list(robot_ids)))
    ws = params.workspace
    roi = crop(fused, ws.min, ws.max)
    raw = len(roi)
    is_obj = ~np.isin(roi.labels, list(background)) & (roi.labels >= 0)
    labels, counts = np.unique(roi.labels[is_obj], return_counts=True)
    target = labels[np.argmax(counts)] if len(labels) else -2  # the most-seen object; the rest are obstacles
    objects = voxel_downsample(roi.select(roi.labels == target), params.voxel_size)
    objects = estimate_normals(objects)
    scene = voxel_downsample(roi.select(is_obj), COLLISION_VOXEL).points
    support = roi.points[~is_obj & (roi.labels >= 0), 2]
    support_z = float(np.median(support)) if len(support) else None
    return Perception(objects, scene, support_z, raw, caps)
