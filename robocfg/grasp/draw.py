"""Candidate grasps drawn on recorded frames (TinyRenderer has no debug lines, so the gripper
outlines are projected with the recorder's own camera and drawn with Pillow).

Each grasp is a U: two fingers (from the fingertips back along the approach, at ±width/2 along
the closing axis), the palm between them, and a stem back along the approach. The best grasp is
green, the others orange. The outlines are kept in the object's frame (its base frame when the
grasps were planned), so they move with the object when it is lifted; a legend says which is which.
"""

from __future__ import annotations

import numpy as np

from robocfg.geometry import quat_to_matrix
from robocfg.sim.record import Recorder

BEST = (40, 220, 60)
OTHER = (255, 150, 30)


def grasp_polylines(grasp, finger_length: float = 0.05, stem: float = 0.04) -> list[np.ndarray]:
    """World-frame polylines (each (k, 3)) outlining a grasp (m)."""
    c, R, h = np.asarray(grasp.center, float), grasp.rotation, grasp.width / 2
    x, y = R[:, 0], R[:, 1]
    tip_l, tip_r = c + h * y, c - h * y
    base_l, base_r = tip_l - finger_length * x, tip_r - finger_length * x
    mid = (base_l + base_r) / 2
    return [np.array([tip_l, base_l, base_r, tip_r]), np.array([mid, mid - stem * x])]


class GraspRecorder(Recorder):
    """A :class:`Recorder` that overlays the grasps given to :meth:`show` on every frame."""

    def __post_init__(self) -> None:
        super().__post_init__()
        self.grasps: list = []
        self.outlines: list[list[np.ndarray]] = []  # per grasp, polylines in the object's frame (m)
        self.obj: int | None = None

    def show(self, grasps, boxes=None, obj: int | None = None) -> None:
        """Draw these grasps (best first) from now on; ``boxes`` (GripperBoxes) sizes the fingers;
        ``obj``: the grasped body, whose motion the outlines follow (None: they stay in place)."""
        self.grasps = list(grasps)
        if boxes is not None:
            x0, x1 = boxes.finger_depth()
            self.finger_length = max(0.01, x1 - x0)
        self.obj = obj
        p0, R0 = self._object_pose()
        self.outlines = [[(line - p0) @ R0 for line in grasp_polylines(g, getattr(self, "finger_length", 0.05))]
                         for g in self.grasps]
        if self.animate:  # hold the planning frame a moment (same picture, three frames)
            frame, info = self.render(), self.info()
            for _ in range(3):
                self.keep(frame, info)

    def _object_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """(position (3,), rotation (3, 3)) of the object now; the world frame without one."""
        if self.obj is None:
            return np.zeros(3), np.eye(3)
        pos, quat = self.world.body_pose(self.obj)
        return np.asarray(pos, float), quat_to_matrix(quat)

    def render(self) -> np.ndarray:
        frame = super().render()
        if not self.outlines:
            return frame
        from PIL import Image, ImageDraw

        img = Image.fromarray(frame)
        draw = ImageDraw.Draw(img)
        p, R = self._object_pose()
        for k, lines in reversed(list(enumerate(self.outlines))):
            for line in lines:
                px, front = self.project(line @ R.T + p)
                if not front.all():
                    continue
                draw.line([tuple(q) for q in px], fill=BEST if k == 0 else OTHER, width=2 if k == 0 else 1)
        _legend(draw, img.size, len(self.outlines))
        return np.asarray(img)


def _legend(draw, size: tuple[int, int], n: int) -> None:
    """Bottom-left key: best grasp, the other candidates."""
    from robocfg.sim.record_overlay import font

    f = font(max(10, size[1] // 26))
    rows = [(BEST, "best grasp")] + ([(OTHER, f"other candidates ({n - 1})")] if n > 1 else [])
    line_h = f.size + 4 if hasattr(f, "size") else 14
    y = size[1] - 6 - line_h * len(rows)
    width = 24 + max(int(draw.textlength(text, font=f)) for _, text in rows)
    draw.rectangle([4, y - 3, 10 + width, size[1] - 4], fill=(255, 255, 255))
    for color, text in rows:
        draw.line([(8, y + line_h // 2), (24, y + line_h // 2)], fill=color, width=3)
        draw.text((28, y), text, fill=(0, 0, 0), font=f)
        y += line_h
