"""Pictures of a world with PyBullet's TinyRenderer (CPU, works headless).

``Recorder(world, "out.gif", fps=15)``: call ``maybe_capture()`` after every ``world.step()``; a frame
is taken whenever ``fps`` says one is due (simulated time). ``save()`` writes an animated GIF
(``.gif``) or the last frame (``.png``). Camera: an orbit camera (``target`` point in world m,
``distance`` m, ``yaw_deg``/``pitch_deg`` as in PyBullet's debug camera).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pybullet as p

from robocfg.errors import RobocfgError


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


@dataclass
class Recorder:
    """Frames of ``world`` at ``fps`` (simulated time) into ``path`` (.gif or .png)."""

    world: object
    path: Path | str
    fps: float = 10.0
    size: tuple[int, int] = (320, 240)
    camera: CameraView = field(default_factory=CameraView)
    max_frames: int = 600
    frames: list[np.ndarray] = field(default_factory=list, init=False)
    _next_t: float = field(default=0.0, init=False)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        if self.path.suffix.lower() not in (".gif", ".png"):
            raise RobocfgError(f"--record needs a .gif or .png file name, got {self.path.name!r}")
        self.animate = self.path.suffix.lower() == ".gif"

    def view_projection(self) -> tuple[list[float], list[float]]:
        """PyBullet's (view, projection) matrices of the camera (column-major 16-lists)."""
        return view_projection(self.world.client, self.camera, self.size)

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates of world points in this recorder's frames (see :func:`project`)."""
        return project(points, self.world.client, self.camera, self.size)

    def render(self) -> np.ndarray:
        """One RGB frame (H, W, 3) uint8 from the current state."""
        return render(self.world.client, self.camera, self.size)

    def capture(self) -> None:
        """Take a frame now (keeps only the last one when saving a .png)."""
        frame = self.render()
        if self.animate:
            if len(self.frames) < self.max_frames:
                self.frames.append(frame)
        else:
            self.frames = [frame]

    def maybe_capture(self) -> None:
        """Capture if a frame is due at the world's current simulated time (PNG: cheap no-op
        until ``save()``, which renders the final state)."""
        if not self.animate:
            return
        if self.world.t + 1e-9 >= self._next_t:
            self.capture()
            self._next_t = self.world.t + 1.0 / self.fps

    def save(self) -> Path:
        """Write the file (a .png renders the current state as its last frame). Returns the path."""
        from PIL import Image

        if not self.animate or not self.frames:
            self.capture()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.animate:
            imgs = [Image.fromarray(f) for f in self.frames]
            imgs[0].save(self.path, save_all=True, append_images=imgs[1:], duration=int(1000 / self.fps), loop=0)
        else:
            Image.fromarray(self.frames[-1]).save(self.path)
        return self.path


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
    a = np.asarray(side_axis, dtype=float)
    n = np.cross([0.0, 0.0, 1.0], a)
    if np.linalg.norm(n[:2]) < 1e-6:  # closing axis vertical: look along x
        n = np.array([1.0, 0.0, 0.0])
    n = n / np.linalg.norm(n)
    if np.dot(n[:2], (t - np.asarray(away_from, dtype=float))[:2]) < 0:
        n = -n
    e = np.radians(elevation_deg)
    eye = t + distance * (np.cos(e) * n + np.sin(e) * np.array([0.0, 0.0, 1.0]))
    return CameraView(target=tuple(t.tolist()), eye=tuple(eye.tolist()))


def fit_camera(lo, hi, direction, fov_deg: float = 50.0, aspect: float = 4 / 3, margin: float = 1.08,
               ) -> CameraView:
    """A camera looking at the centre of the world box [``lo``, ``hi``] (m) from ``direction``
    (a vector from the box towards the eye), just far enough away that every corner of the box is
    in the picture (``margin`` > 1 leaves a border). Works for any robot size, a 1 m tabletop arm
    or a 3 m KR210 on its pedestal alike."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    centre = (lo + hi) / 2
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    f = -d
    u = np.cross(f, [0.0, 0.0, 1.0])
    u = np.array([1.0, 0.0, 0.0]) if np.linalg.norm(u) < 1e-9 else u / np.linalg.norm(u)
    v = np.cross(u, f)
    tv = np.tan(np.radians(fov_deg) / 2)
    th = tv * aspect
    corners = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] for k in range(8)]) - centre
    need = max(float(np.max(np.abs(corners @ u) / th - corners @ f)),
               float(np.max(np.abs(corners @ v) / tv - corners @ f)), 1e-3)
    dist = need * margin
    eye = centre + dist * d
    return CameraView(target=tuple(centre.tolist()), eye=tuple(eye.tolist()), fov_deg=fov_deg,
                      distance=float(dist))
