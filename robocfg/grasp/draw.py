"""Candidate grasps drawn on recorded frames (TinyRenderer has no debug lines, so the gripper
outlines are projected with the recorder's own camera and drawn with Pillow).

Each grasp is a U: two fingers (from the fingertips back along the approach, at ±width/2 along
the closing axis), the palm between them, and a stem back along the approach. The best grasp is
green, the others orange.
"""

from __future__ import annotations

import numpy as np

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

    def show(self, grasps, boxes=None) -> None:
        """Draw these grasps (best first) from now on; ``boxes`` (GripperBoxes) sizes the fingers."""
        self.grasps = list(grasps)
        if boxes is not None:
            x0, x1 = boxes.finger_depth()
            self.finger_length = max(0.01, x1 - x0)
        if self.animate:  # hold the planning frame a moment (same picture, three frames)
            frame, info = self.render(), self.info()
            for _ in range(3):
                self.keep(frame, info)

    def render(self) -> np.ndarray:
        frame = super().render()
        if not self.grasps:
            return frame
        from PIL import Image, ImageDraw

        img = Image.fromarray(frame)
        draw = ImageDraw.Draw(img)
        for k, g in reversed(list(enumerate(self.grasps))):
            for line in grasp_polylines(g, getattr(self, "finger_length", 0.05)):
                px, front = self.project(line)
                if not front.all():
                    continue
                draw.line([tuple(q) for q in px], fill=BEST if k == 0 else OTHER, width=2 if k == 0 else 1)
        return np.asarray(img)
