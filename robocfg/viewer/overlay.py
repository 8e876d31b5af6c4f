"""Frames drawn over a rendered picture with Pillow (TinyRenderer draws no debug lines).

World geometry is projected with the camera that rendered the image
(:func:`robocfg.sim.record.project`); labels are pushed apart so they stay readable where
frames crowd (ee_link, TCP and grasp frame sit a few cm apart on a whole-robot view).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from PIL import Image, ImageDraw

from robocfg.sim.record_overlay import font
from robocfg.viewer.frames import BOX_EDGES, ArmFrames

AXIS_COLORS = ((225, 30, 30), (20, 160, 20), (30, 70, 230))  # x, y, z
ARROW_COLOR = (200, 0, 200)
PAD_COLOR = (255, 140, 0)
COLLISION_COLOR = (0, 170, 190)
TEXT_COLOR = (10, 10, 10)

Projector = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]  # world (N, 3) → pixels (N, 2), in front (N,)


@dataclass
class Labels:
    """Text labels placed beside their anchor points, shifted down until they overlap no other."""

    size: int = 13
    items: list[tuple[tuple[float, float], str, tuple[int, int, int]]] = field(default_factory=list)

    def add(self, anchor: Sequence[float], text: str, color: tuple[int, int, int] = TEXT_COLOR) -> None:
        self.items.append(((float(anchor[0]), float(anchor[1])), text, color))

    def draw(self, draw: ImageDraw.ImageDraw, width: int, height: int) -> None:
        f = font(self.size)
        placed: list[tuple[float, float, float, float]] = []
        for (ax, ay), text, color in sorted(self.items, key=lambda it: it[0][1]):
            x0, t, r, b = draw.textbbox((0, 0), text, font=f)
            w, h = r - x0 + 6, b - t + 4
            x = ax + 12 if ax + 12 + w < width else ax - 12 - w
            y = ay - h - 6
            y = min(max(y, 2), height - h - 2)
            while any(x < px1 and x + w > px0 and y < py1 and y + h > py0 for px0, py0, px1, py1 in placed):
                y += 3
            placed.append((x, y, x + w, y + h))
            draw.line([(ax, ay), (x if x > ax else x + w, y + h / 2)], fill=(90, 90, 90), width=1)
            draw.rectangle([x, y, x + w, y + h], fill=(255, 255, 255), outline=color)
            draw.text((x + 3, y + 2 - t), text, fill=color, font=f)


def _arrow(draw: ImageDraw.ImageDraw, a: np.ndarray, b: np.ndarray, color, width: int) -> None:
    draw.line([tuple(a), tuple(b)], fill=color, width=width)
    d = b - a
    n = float(np.hypot(*d))
    if n < 4:
        return
    d /= n
    head = min(10.0, 0.35 * n)
    side = np.array([-d[1], d[0]])
    pts = [tuple(b), tuple(b - head * d + 0.5 * head * side), tuple(b - head * d - 0.5 * head * side)]
    draw.polygon(pts, fill=color)


def draw_frames(image: Image.Image, frames: Sequence[ArmFrames], project: Projector, labels: Labels,
                tags: dict[str, str] | None = None, axis_names: bool = False, width: int = 3) -> None:
    """Triads, the ``ee_axis`` arrow and pad boxes of every arm onto ``image``. Each triad is
    labelled with ``tags[label]`` if given (short tags explained by a legend), else its full
    label; ``axis_names`` also writes what each axis means at its tip (approach, closing…)."""
    draw = ImageDraw.Draw(image)
    for arm in frames:
        for pad in arm.pads:
            px, front = project(pad.corners)
            if front.all():
                for i, j in BOX_EDGES:
                    draw.line([tuple(px[i]), tuple(px[j])], fill=PAD_COLOR, width=2)
        px, front = project(np.array([arm.ee_axis.start, arm.ee_axis.end]))
        if front.all():
            _arrow(draw, px[0], px[1], ARROW_COLOR, width + 1)
        for tri in arm.triads:
            o = tri.pose[:3, 3]
            tips = o + tri.length * tri.pose[:3, :3].T
            px, front = project(np.vstack([o, tips]))
            if not front.all():
                continue
            for a in range(3):
                _arrow(draw, px[0], px[1 + a], AXIS_COLORS[a], width)
                if axis_names and tri.axis_labels[a] not in ("x", "y", "z"):
                    labels.add(px[1 + a], f"{tri.axis_labels[a]} ({'xyz'[a]})", AXIS_COLORS[a])
            r = width + 1
            draw.ellipse([px[0][0] - r, px[0][1] - r, px[0][0] + r, px[0][1] + r], fill=(0, 0, 0))
            labels.add(px[0], (tags or {}).get(tri.label, tri.label))


def draw_boxes(image: Image.Image, boxes: Sequence[np.ndarray], project: Projector,
               color: tuple[int, int, int] = COLLISION_COLOR) -> None:
    """Wireframes of (8, 3) world boxes (corner order of :data:`BOX_EDGES`)."""
    draw = ImageDraw.Draw(image)
    for corners in boxes:
        px, front = project(corners)
        if front.all():
            for i, j in BOX_EDGES:
                draw.line([tuple(px[i]), tuple(px[j])], fill=color, width=1)
