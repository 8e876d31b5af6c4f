"""Render the task's dataset cameras (``cameras:`` in the task YAML) from a world.

A ``world`` camera is fixed; an ``ee`` camera's position, look-at point and up vector are given in
the arm's ``ee_link`` frame and moved with it every frame. Images come from PyBullet's
TinyRenderer (CPU, headless). Depth is metric along the
optical axis (m), ``far`` where nothing is hit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import pybullet as p

from robocfg.config.cameras import TaskCamera

Renderer = Literal["tiny"]


@dataclass(frozen=True)
class CameraImage:
    """``rgb`` (H, W, 3) uint8; ``depth`` (H, W) float32 m, or None when the camera records none."""

    rgb: np.ndarray
    depth: np.ndarray | None


class CameraRig:
    """The task's cameras on one arm of ``world`` (its ``ee_link`` carries ``mount: ee`` cameras)."""

    def __init__(self, world, arm, cameras: list[TaskCamera], renderer: Renderer = "tiny"):
        self.world, self.arm, self.cameras = world, arm, list(cameras)
        self._renderer = p.ER_TINY_RENDERER

    def render_all(self) -> dict[str, CameraImage]:
        """One image per camera, keyed by camera name, of the world's current state."""
        T_ee = self.arm.ee_pose() if any(c.mount == "ee" for c in self.cameras) else None
        return {c.name: self.render(c, T_ee) for c in self.cameras}

    def render(self, cam: TaskCamera, T_ee: np.ndarray | None = None) -> CameraImage:
        eye, target, up = (np.asarray(v, float) for v in (cam.position, cam.look_at, cam.up))
        if cam.mount == "ee":
            T = self.arm.ee_pose() if T_ee is None else T_ee
            eye, target, up = T[:3, :3] @ eye + T[:3, 3], T[:3, :3] @ target + T[:3, 3], T[:3, :3] @ up
        c = self.world.client
        view = p.computeViewMatrix(eye.tolist(), target.tolist(), up.tolist(), physicsClientId=c)
        proj = p.computeProjectionMatrixFOV(cam.fov_deg, cam.width / cam.height, cam.near, cam.far, physicsClientId=c)
        img = p.getCameraImage(cam.width, cam.height, view, proj, renderer=self._renderer,
                               flags=p.ER_NO_SEGMENTATION_MASK, physicsClientId=c)
        h, w = cam.height, cam.width
        rgb = np.reshape(np.asarray(img[2], np.uint8), (h, w, 4))[:, :, :3].copy()
        depth = None
        if cam.depth:
            buf = np.reshape(np.asarray(img[3], np.float32), (h, w))
            n, f = cam.near, cam.far
            depth = (f * n / (f - (f - n) * buf)).astype(np.float32)
        return CameraImage(rgb, depth)
