"""Where a recording's camera looks: the fitted scene camera, orbit/eye cameras, projection.

Split from :mod:`robocfg.sim.record` (which draws and writes the frames): this module only decides
views. Frames: world, z up, metres; image sizes (width, height) in pixels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet as p

from robocfg.sim.record_overlay import Marker
from robocfg.sim.renderer import require_renderer


@dataclass(frozen=True)
class CameraView:
    """Orbit camera around ``target`` (world frame, m), or looking from ``eye`` when given."""

    target: tuple[float, float, float] = (0.3, 0.0, 0.3)
    distance: float = 1.4
    yaw_deg: float = 45.0
    pitch_deg: float = -25.0
    fov_deg: float = 50.0
    light_direction: tuple[float, float, float] = (1.0, 1.0, 2.0)
    eye: tuple[float, float, float] | None = None  # world m; overrides distance/yaw/pitch
    shadow: bool = False  # shadows cost ≈ 70 % more render time



def task_markers(world) -> list[Marker]:
    """The place target of a pick-place task (circle = success tolerance), if any."""
    task = getattr(world, "task", None)
    params = getattr(getattr(task, "config", None), "pick_place", None)
    if params is None:
        return []
    x, y, _ = params.place_position
    return [Marker("place target", (float(x), float(y), 0.001), float(params.success_tolerance))]


def _work_boxes(world) -> list[tuple[np.ndarray, np.ndarray]]:
    """Where a pick-place hand goes: above the object's start and the place target (the object
    is spawned after the recorder is made, and the hand rises above both)."""
    task = getattr(world, "task", None)
    params = getattr(getattr(task, "config", None), "pick_place", None)
    if params is None:
        return []
    out = []
    for x, y, z in (params.object.position, params.place_position):
        out.append((np.array([x - 0.06, y - 0.06, 0.0]), np.array([x + 0.06, y + 0.06, z + 0.25])))
    return out


DEFAULT_DIRECTION = (1.0, -0.8, 0.75)  # from the scene towards the eye: front right, above


def _facing_work(base, work) -> tuple[float, float, float]:
    """The default view turned about z so that the robot's work area (the object and the place
    target) is in front of the robot as seen from the camera, not hidden behind its pedestal."""
    centre = np.mean([(lo + hi) / 2 for lo, hi in work], axis=0)
    w = centre[:2] - np.asarray(base, float)[:2]
    if np.linalg.norm(w) < 0.1:
        return DEFAULT_DIRECTION
    turn = np.arctan2(w[1], w[0]) + np.arctan2(DEFAULT_DIRECTION[1], DEFAULT_DIRECTION[0])
    r = float(np.hypot(DEFAULT_DIRECTION[0], DEFAULT_DIRECTION[1]))
    return (r * float(np.cos(turn)), r * float(np.sin(turn)), DEFAULT_DIRECTION[2])


def scene_camera(world, size: tuple[int, int] = (320, 240), markers=(), direction=DEFAULT_DIRECTION,
                 margin: float = 1.1) -> CameraView:
    """A camera fitted (see :func:`fit_camera`) to the boxes of every robot link and body of the
    world except the ground, and the markers: a tabletop arm and a KR210 on its pedestal both
    fill the frame. The robot's boxes are taken at its current (start) pose. With a pick-place
    task the default direction is turned so the object and the place target face the camera."""
    c = world.client
    skip = {getattr(world, "bodies", {}).get("ground")}
    boxes = []
    for i in range(p.getNumBodies(physicsClientId=c)):
        bid = p.getBodyUniqueId(i, physicsClientId=c)
        if bid in skip:
            continue
        for li in range(-1, p.getNumJoints(bid, physicsClientId=c)):
            boxes.append(p.getAABB(bid, li, physicsClientId=c))
    for m in markers:
        r = np.array([m.radius, m.radius, 0.0])
        boxes.append((np.asarray(m.position) - r, np.asarray(m.position) + r))
    work = _work_boxes(world)
    boxes += work
    robots = getattr(world, "robots", [])
    if work and robots and direction == DEFAULT_DIRECTION:
        direction = _facing_work(robots[0].base_pose()[:3, 3], work)
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    corners = [[(b[1] if k >> a & 1 else b[0])[a] for a in range(3)] for b in boxes for k in range(8)]
    return fit_camera(lo, hi, direction, aspect=size[0] / size[1], margin=margin, points=corners)


def view_projection(client: int, camera: CameraView, size: tuple[int, int]) -> tuple[list[float], list[float]]:
    """PyBullet's (view, projection) matrices of ``camera`` for a ``size`` = (W, H) image
    (column-major 16-lists, as ``getCameraImage`` takes them)."""
    w, h = size
    if camera.eye is not None:
        up = [0, 0, 1] if np.linalg.norm(np.cross(np.subtract(camera.target, camera.eye), [0, 0, 1])) > 1e-9 else [0, 1, 0]
        view = p.computeViewMatrix(list(camera.eye), list(camera.target), up, physicsClientId=client)
    else:
        view = p.computeViewMatrixFromYawPitchRoll(list(camera.target), camera.distance, camera.yaw_deg,
                                                   camera.pitch_deg, 0.0, 2, physicsClientId=client)
    proj = p.computeProjectionMatrixFOV(camera.fov_deg, w / h, 0.02, 50.0, physicsClientId=client)
    return view, proj


def render(client: int, camera: CameraView, size: tuple[int, int]) -> np.ndarray:
    """One RGB image (H, W, 3) uint8 of the client's bodies seen by ``camera`` (TinyRenderer)."""
    require_renderer(client)
    w, h = size
    view, proj = view_projection(client, camera, size)
    img = p.getCameraImage(w, h, view, proj, renderer=p.ER_TINY_RENDERER, shadow=int(camera.shadow),
                           lightDirection=list(camera.light_direction), physicsClientId=client)
    rgba = np.reshape(np.asarray(img[2], dtype=np.uint8), (h, w, 4))
    return rgba[:, :, :3].copy()


def project(points, client: int, camera: CameraView, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """World points (N, 3) m → (pixels (N, 2) as (column, row) floats, in-front mask (N,)) in an
    image rendered by :func:`render` with the same camera and size. TinyRenderer draws no debug
    lines, so overlays are projected with this and drawn with Pillow."""
    view, proj = view_projection(client, camera, size)
    M = np.asarray(proj, float).reshape(4, 4).T @ np.asarray(view, float).reshape(4, 4).T
    P = np.atleast_2d(np.asarray(points, float))
    clip = np.c_[P, np.ones(len(P))] @ M.T
    front = clip[:, 3] > 1e-9
    ndc = clip[:, :2] / np.where(front, clip[:, 3], 1.0)[:, None]
    w, h = size
    return np.c_[(ndc[:, 0] + 1) / 2 * w, (1 - ndc[:, 1]) / 2 * h], front


def facing_camera(target, side_axis, away_from, distance: float = 0.5, elevation_deg: float = 20.0) -> CameraView:
    """A camera looking at ``target`` from the horizontal direction perpendicular to ``side_axis``
    (e.g. a gripper's closing axis, so both fingers are seen side by side), on the side of ``target``
    away from the point ``away_from`` (e.g. the robot base), raised by ``elevation_deg``."""
    t = np.asarray(target, dtype=float)
    eye = t + distance * facing_direction(t, side_axis, away_from, elevation_deg)
    return CameraView(target=tuple(t.tolist()), eye=tuple(eye.tolist()))


def facing_direction(target, side_axis, away_from, elevation_deg: float = 20.0) -> np.ndarray:
    """The unit vector from ``target`` towards the eye of :func:`facing_camera` (world frame)."""
    t = np.asarray(target, dtype=float)
    a = np.asarray(side_axis, dtype=float)
    n = np.cross([0.0, 0.0, 1.0], a)
    if np.linalg.norm(n[:2]) < 1e-6:  # closing axis vertical: look along x
        n = np.array([1.0, 0.0, 0.0])
    n = n / np.linalg.norm(n)
    if np.dot(n[:2], (t - np.asarray(away_from, dtype=float))[:2]) < 0:
        n = -n
    e = np.radians(elevation_deg)
    return np.cos(e) * n + np.sin(e) * np.array([0.0, 0.0, 1.0])


def fit_camera(lo, hi, direction, fov_deg: float = 50.0, aspect: float = 4 / 3, margin: float = 1.08,
               points=None) -> CameraView:
    """A camera looking from ``direction`` (a vector from the scene towards the eye) at the world
    box [``lo``, ``hi``] (m), just far enough away that every corner of the box is in the picture
    (``margin`` > 1 leaves a border). Works for any robot size, a 1 m tabletop arm or a 3 m KR210
    on its pedestal alike. ``points`` (N, 3): frame these instead of the box's corners (e.g. the
    corners of every link's box: seen obliquely, the big box's far corners leave the picture's
    corners empty); the view is centred on their extent across the image."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    centre = (lo + hi) / 2
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    f = -d
    u = np.cross(f, [0.0, 0.0, 1.0])
    u = np.array([1.0, 0.0, 0.0]) if np.linalg.norm(u) < 1e-9 else u / np.linalg.norm(u)
    v = np.cross(u, f)
    if points is None:
        pts = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] for k in range(8)])
    else:
        pts = np.asarray(points, float).reshape(-1, 3)
        rel = pts - centre
        a, b = rel @ u, rel @ v
        centre = centre + u * (a.max() + a.min()) / 2 + v * (b.max() + b.min()) / 2
    tv = np.tan(np.radians(fov_deg) / 2)
    th = tv * aspect
    corners = pts - centre
    need = max(float(np.max(np.abs(corners @ u) / th - corners @ f)),
               float(np.max(np.abs(corners @ v) / tv - corners @ f)), 1e-3)
    dist = need * margin
    eye = centre + dist * d
    return CameraView(target=tuple(centre.tolist()), eye=tuple(eye.tolist()), fov_deg=fov_deg,
                      distance=float(dist))
