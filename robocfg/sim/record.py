"""Pictures of a world with PyBullet's TinyRenderer (CPU, works headless).

``Recorder(world, "out.gif", fps=15)``: call ``maybe_capture()`` after every ``world.step()``; a frame
is rendered only when ``fps`` says one is due (simulated time). ``save()`` writes an animated GIF
(``.gif``), an MP4 (``.mp4``), the last frame (``.png``) or a contact sheet (``*sheet.png``).
Camera: fitted to the scene by default; else an orbit camera (``target`` point in world m,
``distance`` m, ``yaw_deg``/``pitch_deg`` as in PyBullet's debug camera) or an ``eye`` point.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pybullet as p

from robocfg.errors import RobocfgError
from robocfg.sim.record_overlay import FrameInfo, Marker, contact_sheet, draw_markers, draw_status
from robocfg.sim.record_settings import RecordSettings
from robocfg.sim.render_mirror import MAX_FACES, RenderMirror

if TYPE_CHECKING:
    from robocfg.sim.world import World


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
    """Frames of ``world`` at ``fps`` (simulated time) into ``path``.

    ``path``: ``.gif`` (animation), ``.mp4`` (H.264 video), ``.png`` (the last frame), or a
    ``.png`` whose name ends in ``sheet`` (``run_sheet.png``: a contact sheet of key frames, one
    per phase). ``camera`` None: :func:`scene_camera` fits one to the robots and the task's bodies.
    ``overlay``: a status bar (time, phase, gripper opening), the place target with its tolerance,
    and a success/failure banner at the end. Runners call :meth:`set_phase` and :meth:`finish`.
    ``renderer``: ``"tiny"`` draws frames from a :class:`RenderMirror` of the world, TinyRenderer
    on the CPU with every visual mesh cut to ``max_faces`` triangles and the static bodies drawn
    once (≈ 5× cheaper than drawing the world itself, the picture alike); ``"exact"`` draws the
    world's own meshes (as shadows do); ``"egl"`` draws the mirror with PyBullet's EGL plugin
    (OpenGL, for a GPU). None: the ``ROBOCFG_RENDERER`` environment variable, else ``"egl"`` where
    an NVIDIA GPU is present and its plugin loads, else ``"tiny"``.
    """

    world: World
    path: Path | str
    fps: float = 10.0
    size: tuple[int, int] = (320, 240)
    camera: CameraView | None = None
    max_frames: int = 600
    overlay: bool = True
    max_faces: int | None = MAX_FACES
    renderer: str | None = None
    settings: RecordSettings | None = None  # the user's camera / size / fps: override the run's choice
    frames: list[np.ndarray] = field(default_factory=list, init=False)
    infos: list[FrameInfo] = field(default_factory=list, init=False)
    markers: list[Marker] = field(default_factory=list, init=False)
    phase: str = field(default="", init=False)
    result: tuple[bool, str] | None = field(default=None, init=False)
    _next_t: float = field(default=0.0, init=False)
    _mirror: RenderMirror | None = field(default=None, init=False, repr=False)
    _markers_drawn: tuple | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        kind = self.path.suffix.lower()
        if kind not in (".gif", ".png", ".mp4"):
            raise RobocfgError(f"--record needs a .gif, .mp4 or .png file name, got {self.path.name!r}")
        self.sheet = kind == ".png" and self.path.stem.lower().endswith("sheet")
        self.animate = kind != ".png" or self.sheet
        self.markers = task_markers(self.world)
        if self.settings is not None:
            self._apply(self.settings)
        self.renderer = self.renderer or os.environ.get("ROBOCFG_RENDERER", "auto")
        if self.renderer not in RENDERERS:
            raise RobocfgError(f"unknown renderer {self.renderer!r}: one of {', '.join(RENDERERS)}")
        if self.camera is None:
            self.camera = scene_camera(self.world, self.size, self.markers)

    def _apply(self, s: RecordSettings) -> None:
        if s.size is not None:
            self.size = s.size
        if s.fps is not None:
            self.fps = s.fps
        if s.camera is not None:
            c = s.camera
            self.camera = CameraView(target=c.target, distance=c.distance, yaw_deg=c.yaw_deg, pitch_deg=c.pitch_deg)

    def view_projection(self) -> tuple[list[float], list[float]]:
        """PyBullet's (view, projection) matrices of the camera (column-major 16-lists)."""
        return view_projection(self.world.client, self.camera, self.size)

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates of world points in this recorder's frames (see :func:`project`)."""
        return project(points, self.world.client, self.camera, self.size)

    def render(self) -> np.ndarray:
        """One RGB frame (H, W, 3) uint8 from the current state (no status overlay)."""
        if self.renderer == "exact" or self.camera.shadow:
            return render(self.world.client, self.camera, self.size)
        if self._mirror is None:
            self._mirror = make_mirror(self.world.client, self.renderer, self.max_faces)
        view, proj = self.view_projection()
        return self._mirror.render(view, proj, self.size, self.camera.light_direction)

    def close(self) -> None:
        """Free the render mirror's PyBullet clients (:meth:`save` does it too)."""
        if self._mirror is not None:
            self._mirror.close()
            self._mirror = None

    def set_phase(self, name: str) -> None:
        """Name the phase shown from the next frame on."""
        self.phase = name

    def finish(self, success: bool, reason: str = "") -> None:
        """Mark the run's outcome: the last frame is re-taken with a SUCCESS/FAILED banner."""
        self.result = (bool(success), reason)

    def info(self) -> FrameInfo:
        """Time, phase and first gripper's opening now."""
        opening = None
        robots = getattr(self.world, "robots", [])
        if robots:
            g = robots[0].arm().gripper
            w = g.width() if g is not None else None
            opening = None if w is None else float(w)
        return FrameInfo(float(getattr(self.world, "t", 0.0)), self.phase, opening)

    def _decorated(self, frame: np.ndarray, info: FrameInfo, result=None) -> np.ndarray:
        if not self.overlay:
            return frame
        from PIL import Image

        img = Image.fromarray(frame)
        if self.markers:
            layer = self._marker_layer()
            img.paste(layer, (0, 0), layer)
        draw_status(img, info, result)
        return np.asarray(img)

    def _marker_layer(self):
        """The markers drawn once on a transparent image (the camera does not move)."""
        from PIL import Image

        key = (self.camera, self.size)
        if self._markers_drawn is None or self._markers_drawn[0] != key:
            layer = Image.new("RGBA", self.size, (0, 0, 0, 0))
            draw_markers(layer, self.markers, self.project)
            self._markers_drawn = (key, layer)
        return self._markers_drawn[1]

    def keep(self, frame: np.ndarray, info: FrameInfo | None = None) -> None:
        """Store a rendered frame (with overlays) as the next one."""
        info = info or self.info()
        if self.animate:
            if len(self.frames) < self.max_frames:
                self.frames.append(self._decorated(frame, info))
                self.infos.append(info)
        else:
            self.frames, self.infos = [self._decorated(frame, info)], [info]

    def capture(self) -> None:
        """Take a frame now (keeps only the last one when saving a single .png)."""
        self.keep(self.render())

    def maybe_capture(self) -> None:
        """Capture if a frame is due at the world's current simulated time (PNG: cheap no-op
        until ``save()``, which renders the final state). Only kept frames are rendered."""
        if not self.animate:
            return
        if self.world.t + 1e-9 >= self._next_t:
            self.capture()
            self._next_t = self.world.t + 1.0 / self.fps

    def save(self) -> Path:
        """Write the file (the current state is rendered as the last frame). Returns the path."""
        from PIL import Image

        info = self.info()
        last = self._decorated(self.render(), info, self.result)
        if self.animate and len(self.frames) >= self.max_frames:
            self.frames, self.infos = self.frames[:-1], self.infos[:-1]
        self.frames.append(last)
        self.infos.append(info)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        if self.sheet:
            contact_sheet(self.frames, self.infos).save(self.path)
        elif not self.animate:
            Image.fromarray(last).save(self.path)
        elif self.path.suffix.lower() == ".mp4":
            write_mp4(self.path, self.frames, self.fps)
        else:
            hold = [*self.frames, *([last] * max(1, int(self.fps)))]  # the result stays up ≈ 1 s
            write_gif(self.path, hold, self.fps)
        self.close()
        return self.path


RENDERERS = ("auto", "tiny", "exact", "egl")


def make_mirror(client: int, renderer: str, max_faces: int | None) -> RenderMirror:
    """The render mirror for ``renderer`` (``"auto"``: EGL where an NVIDIA GPU is present and the
    plugin loads, else TinyRenderer)."""
    if renderer == "egl" or (renderer == "auto" and Path("/dev/nvidiactl").exists()):
        try:
            return RenderMirror(client, max_faces, egl=True)
        except RobocfgError:
            if renderer == "egl":
                raise
    return RenderMirror(client, max_faces)


def write_gif(path: Path, frames: list[np.ndarray], fps: float) -> None:
    """Animated GIF with one palette for all frames, taken from the first, middle and last frame
    (the scene changes little; a palette per frame costs ≈ 6× more and makes colours flicker)."""
    from PIL import Image

    probe = np.concatenate([frames[0], frames[len(frames) // 2], frames[-1]], axis=0)
    palette = Image.fromarray(probe).quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    imgs = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    imgs[0].save(path, save_all=True, append_images=imgs[1:], duration=int(1000 / fps), loop=0)


def write_mp4(path: Path, frames: list[np.ndarray], fps: float) -> None:
    """H.264 MP4 (yuv420p, so every player opens it) with PyAV; odd sizes are padded by a pixel."""
    from fractions import Fraction

    import av

    h, w = frames[0].shape[:2]
    H, W = h + h % 2, w + w % 2
    with av.open(str(path), mode="w") as out:
        stream = out.add_stream("libx264", rate=Fraction(fps).limit_denominator(1000))
        stream.width, stream.height, stream.pix_fmt = W, H, "yuv420p"
        for f in [*frames, frames[-1]]:
            if (h, w) != (H, W):
                f = np.pad(f, ((0, H - h), (0, W - w), (0, 0)), mode="edge")
            for packet in stream.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(f), format="rgb24")):
                out.mux(packet)
        for packet in stream.encode():
            out.mux(packet)


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
