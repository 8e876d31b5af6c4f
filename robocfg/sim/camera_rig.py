"""Render the task's dataset cameras (``cameras:`` in the task YAML) from a world.

A ``world`` camera is fixed; an ``ee`` camera's position, look-at point and up vector are given in
the arm's ``ee_link`` frame and moved with it every frame. Depth is metric along the optical axis
(m), ``far`` where nothing is hit.

``renderer`` picks how images are drawn, as for ``--record`` (:mod:`robocfg.sim.render_mirror`):

* ``"tiny"``: a :class:`~robocfg.sim.render_mirror.RenderMirror` of the world — TinyRenderer (CPU)
  on low-poly copies of the visual meshes, the static bodies drawn once per fixed camera;
* ``"egl"``: the same mirror drawn by PyBullet's EGL plugin (OpenGL; fast on a GPU);
* ``"auto"`` (default): ``egl`` where an NVIDIA GPU is present and the plugin loads, else ``tiny``;
* ``"exact"``: TinyRenderer on the world itself, full meshes (the slowest; pictures as PyBullet
  draws the world).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import pybullet as p

from robocfg.config.cameras import TaskCamera
from robocfg.sim.low_poly import MAX_FACES
from robocfg.sim.render_mirror import RenderMirror, make_mirror
from robocfg.sim.renderer import require_renderer

Renderer = Literal["auto", "tiny", "exact", "egl"]


@dataclass(frozen=True)
class CameraImage:
    """``rgb`` (H, W, 3) uint8; ``depth`` (H, W) float32 m, or None when the camera records none."""

    rgb: np.ndarray
    depth: np.ndarray | None


class CameraRig:
    """The task's cameras on one arm of ``world`` (its ``ee_link`` carries ``mount: ee`` cameras);
    ``renderer``: see the module docstring. ``close()`` frees a mirror's PyBullet clients."""

    def __init__(self, world, arm, cameras: list[TaskCamera], renderer: Renderer = "auto"):
        self.world, self.arm, self.cameras = world, arm, list(cameras)
        self.renderer = renderer
        self._mirror: RenderMirror | None = None
        self._proj: dict[str, list[float]] = {}

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
        require_renderer(c)
        view = p.computeViewMatrix(eye.tolist(), target.tolist(), up.tolist(), physicsClientId=c)
        proj = self._proj.get(cam.name)
        if proj is None:
            proj = self._proj[cam.name] = list(p.computeProjectionMatrixFOV(
                cam.fov_deg, cam.width / cam.height, cam.near, cam.far, physicsClientId=c))
        h, w = cam.height, cam.width
        if self.renderer == "exact":
            img = p.getCameraImage(w, h, view, proj, renderer=p.ER_TINY_RENDERER, flags=p.ER_NO_SEGMENTATION_MASK,
                                   physicsClientId=c)
            rgb = np.reshape(np.asarray(img[2], np.uint8), (h, w, 4))[:, :, :3].copy()
            buf = np.reshape(np.asarray(img[3], np.float32), (h, w)) if cam.depth else None
        else:
            if self._mirror is None:
                self._mirror = make_mirror(c, self.renderer, MAX_FACES)
            rgb, buf = self._mirror.render_rgbd(list(view), proj, (w, h))
        depth = None
        if cam.depth and buf is not None:
            n, f = cam.near, cam.far
            depth = (f * n / (f - (f - n) * buf)).astype(np.float32)
        return CameraImage(rgb, depth)

    def close(self) -> None:
        if self._mirror is not None:
            self._mirror.close()
            self._mirror = None
