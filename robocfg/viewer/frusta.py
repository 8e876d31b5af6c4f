"""The task's dataset cameras (``cameras:`` in the task YAML) as frusta in the browser viewer.

A camera's pose follows the convention viser draws frusta in (OpenCV: x right, y down, z along
the optical axis). ``mount: world`` cameras stand still; ``mount: ee`` cameras are given in the
first arm's ``ee_link`` frame and move with it, so the viewer re-poses them when the arm moves.
Units: m, rad.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robocfg.config.cameras import TaskCamera

if TYPE_CHECKING:
    import viser

FRUSTUM_COLOR = (30, 120, 255)
Wxyz = tuple[float, float, float, float]  # a quaternion as viser takes it


def camera_pose(cam: TaskCamera, T_mount: np.ndarray | None = None) -> np.ndarray:
    """World pose (4x4) of ``cam``'s optical frame (x right, y down, z forward). ``T_mount``: the
    world pose of the ``ee_link`` for a ``mount: ee`` camera (ignored for ``mount: world``)."""
    eye, target, up = (np.asarray(v, float) for v in (cam.position, cam.look_at, cam.up))
    if cam.mount == "ee" and T_mount is not None:
        R, t = T_mount[:3, :3], T_mount[:3, 3]
        eye, target, up = R @ eye + t, R @ target + t, R @ up
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, up)
    if np.linalg.norm(x) < 1e-9:  # looking along the up hint: any right-angle will do
        x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = eye
    return T


@dataclass
class ShownCamera:
    """A frustum on the page: its camera and the scene handle to re-pose."""

    camera: TaskCamera
    handle: viser.CameraFrustumHandle

    def place(self, T_ee: np.ndarray | None, wxyz: Callable[[np.ndarray], Wxyz]) -> None:
        """Pose the frustum (``T_ee``: the world pose of the ``ee_link``, for ``mount: ee``)."""
        T = camera_pose(self.camera, T_ee)
        self.handle.position = (float(T[0, 3]), float(T[1, 3]), float(T[2, 3]))
        self.handle.wxyz = wxyz(T[:3, :3])


def add_frusta(server: viser.ViserServer, cameras: list[TaskCamera], T_ee: np.ndarray | None,
               wxyz: Callable[[np.ndarray], Wxyz]) -> list[ShownCamera]:
    """A labelled frustum per camera under ``/cameras`` (depth of the drawing: 0.12 m)."""
    out = []
    for cam in cameras:
        handle = server.scene.add_camera_frustum(f"/cameras/{cam.name}", fov=float(np.radians(cam.fov_deg)),
                                                 aspect=cam.width / cam.height, scale=0.12, color=FRUSTUM_COLOR)
        server.scene.add_label(f"/cameras/{cam.name}/label", f"camera {cam.name} ({cam.mount})")
        shown = ShownCamera(cam, handle)
        shown.place(T_ee, wxyz)
        out.append(shown)
    return out
