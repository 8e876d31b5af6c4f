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

from robocfg.errors import RobocfgError
from robocfg.sim.low_poly import MAX_FACES
from robocfg.sim.record_camera import (
    CameraView,
    project,
    render,
    scene_camera,
    task_markers,
    view_projection,
)
from robocfg.sim.record_overlay import FrameInfo, Marker, contact_sheet, draw_markers, draw_status
from robocfg.sim.record_settings import RecordSettings
from robocfg.sim.render_mirror import RENDERERS, RenderMirror, make_mirror

if TYPE_CHECKING:
    from robocfg.sim.world import World


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
    _renderer: str = field(default="auto", init=False, repr=False)  # ``renderer`` resolved

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
        self.renderer = self._renderer = self.renderer or os.environ.get("ROBOCFG_RENDERER", "auto")
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

    @property
    def view(self) -> CameraView:
        """The camera frames are taken from: ``camera``, or one fitted to the scene when None."""
        if self.camera is None:
            self.camera = scene_camera(self.world, self.size, self.markers)
        return self.camera

    def view_projection(self) -> tuple[list[float], list[float]]:
        """PyBullet's (view, projection) matrices of the camera (column-major 16-lists)."""
        return view_projection(self.world.client, self.view, self.size)

    def project(self, points) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates of world points in this recorder's frames (see :func:`project`)."""
        return project(points, self.world.client, self.view, self.size)

    def render(self) -> np.ndarray:
        """One RGB frame (H, W, 3) uint8 from the current state (no status overlay)."""
        if self._renderer == "exact" or self.view.shadow:
            return render(self.world.client, self.view, self.size)
        if self._mirror is None:
            self._mirror = make_mirror(self.world.client, self._renderer, self.max_faces)
        view, proj = self.view_projection()
        return self._mirror.render(view, proj, self.size, self.view.light_direction)

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
        path = Path(self.path)
        path.parent.mkdir(parents=True, exist_ok=True)
        if self.sheet:
            contact_sheet(self.frames, self.infos).save(path)
        elif not self.animate:
            Image.fromarray(last).save(path)
        elif path.suffix.lower() == ".mp4":
            write_mp4(path, self.frames, self.fps)
        else:
            hold = [*self.frames, *([last] * max(1, int(self.fps)))]  # the result stays up ≈ 1 s
            write_gif(path, hold, self.fps)
        self.close()
        return path


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
