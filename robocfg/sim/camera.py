"""A simulated pinhole RGB-D camera (PyBullet TinyRenderer, headless) and exact back-projection.

Frames: the camera looks from ``position`` at ``look_at`` (world, m) with ``up`` as the image's up
hint; ``fov_deg`` is the vertical field of view. Depth is the metric distance along the optical
axis (m); the world point of a pixel is recovered by inverting OpenGL's projection·view matrix,
so it is exact for any pose and intrinsics (no separate fx/fy bookkeeping to get wrong).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pybullet as p

from robocfg.config.commands import Camera
from robocfg.sim.renderer import require_renderer


@dataclass(frozen=True)
class RGBD:
    """One capture: ``rgb`` (H, W, 3) uint8, ``depth`` (H, W) metric depth along the optical axis
    (m, ``inf`` where nothing was hit), ``seg`` (H, W) PyBullet body id per pixel (−1: none),
    ``points`` (H, W, 3) world coordinates (m; NaN where nothing was hit), ``eye`` (3,)."""

    rgb: np.ndarray
    depth: np.ndarray
    seg: np.ndarray
    points: np.ndarray
    eye: np.ndarray

    def valid(self) -> np.ndarray:
        return np.isfinite(self.depth)


def matrices(cam: Camera) -> tuple[np.ndarray, np.ndarray]:
    """(view, projection) as row-major 4x4 arrays (OpenGL conventions, as PyBullet uses them)."""
    up = _up_vector(cam)
    view = p.computeViewMatrix(list(cam.position), list(cam.look_at), list(up))
    proj = p.computeProjectionMatrixFOV(cam.fov_deg, cam.width / cam.height, cam.near, cam.far)
    return np.asarray(view, float).reshape(4, 4).T, np.asarray(proj, float).reshape(4, 4).T


def _up_vector(cam: Camera) -> np.ndarray:
    """``cam.up`` made usable: if it is (nearly) parallel to the viewing direction, pick another."""
    fwd = np.subtract(cam.look_at, cam.position)
    fwd = fwd / max(np.linalg.norm(fwd), 1e-12)
    up = np.asarray(cam.up, float)
    if np.linalg.norm(np.cross(fwd, up)) < 1e-6:
        up = np.array([1.0, 0.0, 0.0]) if abs(fwd[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    return up


def capture(client: int, cam: Camera, rng: np.random.Generator | None = None) -> RGBD:
    """Render ``cam`` in the world ``client``; depth noise (``depth_noise_std``, m, Gaussian along
    the optical axis) needs ``rng``."""
    require_renderer(client)
    view, proj = matrices(cam)
    w, h = cam.width, cam.height
    img = p.getCameraImage(w, h, view.T.reshape(-1).tolist(), proj.T.reshape(-1).tolist(),
                           renderer=p.ER_TINY_RENDERER, physicsClientId=client)
    rgb = np.reshape(np.asarray(img[2], np.uint8), (h, w, 4))[:, :, :3].copy()
    buf = np.reshape(np.asarray(img[3], float), (h, w))
    seg = np.reshape(np.asarray(img[4], np.int64), (h, w))
    seg = np.where(seg >= 0, seg & ((1 << 24) - 1), -1)
    n, f = cam.near, cam.far
    hit = buf < 1.0 - 1e-7
    depth = np.where(hit, f * n / (f - (f - n) * buf), np.inf)
    if cam.depth_noise_std > 0 and rng is not None:
        depth = np.where(hit, depth + rng.normal(0.0, cam.depth_noise_std, depth.shape), np.inf)
        depth = np.where(depth > n, depth, np.inf)
        hit = np.isfinite(depth)
    points = backproject(depth, view, proj)
    return RGBD(rgb, depth, seg, points, np.asarray(cam.position, float))


def backproject(depth: np.ndarray, view: np.ndarray, proj: np.ndarray) -> np.ndarray:
    """World points (H, W, 3) of a metric depth image (m along the optical axis; non-finite →
    NaN) rendered with row-major ``view`` and ``proj`` (OpenGL; row 0 at the top)."""
    h, w = depth.shape
    n, f = _near_far(proj)
    # TinyRenderer samples pixel (i, j) at NDC x = 2i/w − 1 and y = 1 − 2(j + 1)/h (measured: this
    # puts a box's back-projected faces where the box is, to < 0.1 mm; pixel centres would be 0.5 px off)
    u = np.arange(w) / w * 2.0 - 1.0
    v = 1.0 - (np.arange(h) + 1.0) / h * 2.0
    X, Y = np.meshgrid(u, v)
    with np.errstate(divide="ignore", invalid="ignore"):
        Z = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * depth)
    ndc = np.stack([X, Y, Z, np.ones_like(Z)], axis=-1)
    inv = np.linalg.inv(proj @ view)
    world = ndc @ inv.T
    pts = world[..., :3] / world[..., 3:4]
    pts[~np.isfinite(depth)] = np.nan
    return pts


def _near_far(proj: np.ndarray) -> tuple[float, float]:
    a, b = proj[2, 2], proj[2, 3]  # a = -(f+n)/(f-n), b = -2fn/(f-n)
    return b / (a - 1.0), b / (a + 1.0)


def sees_box(cam: Camera, lo, hi) -> bool:
    """True if the centre of the box [lo, hi] (world, m) lies inside the camera's view frustum
    (between near and far, within the field of view)."""
    view, proj = matrices(cam)
    c = (np.asarray(lo, float) + np.asarray(hi, float)) / 2.0
    clip = proj @ view @ np.append(c, 1.0)
    if clip[3] <= 0:
        return False
    ndc = clip[:3] / clip[3]
    return bool(np.all(np.abs(ndc) <= 1.0))


def look_direction(cam: Camera) -> np.ndarray:
    d = np.subtract(cam.look_at, cam.position)
    return d / max(float(np.linalg.norm(d)), 1e-12)


def pixel_size(cam: Camera, distance: float) -> float:
    """Width (m) one pixel covers at ``distance`` m along the optical axis."""
    return 2.0 * distance * math.tan(math.radians(cam.fov_deg) / 2.0) / cam.height
