"""What a recorded frame says besides the picture: a status bar (time, phase, gripper opening),
world markers (the place target with its tolerance), a result banner, and the contact sheet.

Markers are world geometry projected with the recorder's camera and drawn with Pillow
(TinyRenderer has no debug lines). Units: s, m (the bar shows the gripper opening in mm).
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw, ImageFont

OK_COLOR, FAIL_COLOR, TARGET_COLOR = (20, 150, 40), (200, 30, 30), (20, 170, 60)


@lru_cache(maxsize=16)
def font(size: int) -> ImageFont.ImageFont | ImageFont.FreeTypeFont:
    """DejaVu Sans shipped with matplotlib (has −, →, × glyphs), else Pillow's bundled font.
    The file is found without importing matplotlib (that import alone costs ≈ 0.5 s)."""
    spec = importlib.util.find_spec("matplotlib")
    roots = list(spec.submodule_search_locations or []) if spec is not None else []
    for root in roots:
        path = Path(root) / "mpl-data" / "fonts" / "ttf" / "DejaVuSans.ttf"
        if path.is_file():
            return ImageFont.truetype(str(path), size)
    return ImageFont.load_default(size=size)


@dataclass(frozen=True)
class Marker:
    """A horizontal circle of ``radius`` m around ``position`` (world m), labelled."""

    label: str
    position: tuple[float, float, float]
    radius: float
    color: tuple[int, int, int] = TARGET_COLOR


@dataclass(frozen=True)
class FrameInfo:
    """What was true when a frame was taken: simulated time (s), phase, gripper opening (m)."""

    t: float
    phase: str = ""
    opening: float | None = None

    def text(self) -> str:
        parts = [f"t = {self.t:5.2f} s"]
        if self.phase:
            parts.append(f"phase: {self.phase}")
        if self.opening is not None:
            parts.append(f"gripper {self.opening * 1000:.0f} mm")
        return "   ".join(parts)


def circle_points(m: Marker, n: int = 32) -> np.ndarray:
    """(n + 1, 3) closed polyline of the marker's circle (world m)."""
    a = np.linspace(0.0, 2 * np.pi, n + 1)
    return np.c_[m.position[0] + m.radius * np.cos(a), m.position[1] + m.radius * np.sin(a),
                 np.full(n + 1, m.position[2])]


def draw_markers(img: Image.Image, markers, project) -> None:
    """Each marker's circle, a cross at its centre, and its label. ``project``: world (N, 3) →
    (pixels (N, 2), in front (N,))."""
    draw = ImageDraw.Draw(img)
    f = font(max(10, img.height // 28))
    for m in markers:
        px, front = project(circle_points(m))
        if not front.all():
            continue
        draw.line([tuple(q) for q in px], fill=m.color, width=2)
        c, _ = project(np.array([m.position]))
        x, y = c[0]
        draw.line([(x - 5, y), (x + 5, y)], fill=m.color, width=2)
        draw.line([(x, y - 5), (x, y + 5)], fill=m.color, width=2)
        draw.text((float(px[:, 0].max()) + 3, y - 6), m.label, fill=m.color, font=f,
                  stroke_width=2, stroke_fill=(255, 255, 255))


def draw_status(img: Image.Image, info: FrameInfo, result: tuple[bool, str] | None = None) -> None:
    """A translucent bar on top with ``info``; with ``result`` (success, reason) a banner below it."""
    draw = ImageDraw.Draw(img, "RGBA")
    size = max(10, img.height // 22)
    f = font(size)
    draw.rectangle([0, 0, img.width, size + 8], fill=(255, 255, 255, 200))
    draw.text((6, 3), info.text(), fill=(0, 0, 0), font=f)
    if result is not None:
        ok, reason = result
        text = "SUCCESS" if ok else f"FAILED{': ' + reason if reason else ''}"
        fb = font(size + 2)
        w = draw.textlength(text, font=fb)
        y = size + 12
        draw.rectangle([4, y, 14 + w, y + size + 10], fill=(*(OK_COLOR if ok else FAIL_COLOR), 230))
        draw.text((9, y + 3), text, fill=(255, 255, 255), font=fb)


def contact_sheet(frames: list[np.ndarray], infos: list[FrameInfo], columns: int = 4,
                  per_phase: int = 1) -> Image.Image:
    """Key frames in a grid, each captioned: the first ``per_phase`` frames of every phase (in
    order) and the last frame; without phases, up to 12 frames evenly spaced in time."""
    idx: list[int] = []
    if any(i.phase for i in infos):
        seen: dict[str, int] = {}
        for k, info in enumerate(infos):
            if seen.get(info.phase, 0) < per_phase:
                seen[info.phase] = seen.get(info.phase, 0) + 1
                idx.append(k)
    else:
        idx = sorted(set(np.linspace(0, len(frames) - 1, min(12, len(frames))).round().astype(int).tolist()))
    if len(frames) - 1 not in idx:
        idx.append(len(frames) - 1)
    h, w = frames[0].shape[:2]
    cap = max(12, h // 14)
    rows = -(-len(idx) // columns)
    sheet = Image.new("RGB", (columns * w, rows * (h + cap + 6)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    f = font(cap - 2)
    for n, k in enumerate(idx):
        x, y = (n % columns) * w, (n // columns) * (h + cap + 6)
        sheet.paste(Image.fromarray(frames[k]), (x, y + cap + 4))
        caption = f"{infos[k].phase or 'start'} @ {infos[k].t:.2f} s" + (" (last)" if k == len(frames) - 1 else "")
        draw.text((x + 4, y + 2), caption, fill=(0, 0, 0), font=f)
    return sheet
