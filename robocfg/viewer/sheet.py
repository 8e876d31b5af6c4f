"""``robocfg view --png``: one sheet with four views of a robot (or a task's scene) and its frames.

Panels: front (camera on +x), side (camera on −y), top (camera on +z) and a close-up of the tool
of the first arm seen across its closing axis, so both fingers show side by side. Each camera is
fitted to what it shows (the robots' and scenery's bounding box; the tool's frames and pads), so
a 3 m KR210 fills its panel as well as a Panda does. A header gives the frame numbers from the
YAML; a legend explains colours and tags. Frames are drawn as in :mod:`robocfg.viewer.frames`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from PIL import Image, ImageDraw

from robocfg.sim.record_camera import CameraView, facing_direction, fit_camera, project, render
from robocfg.sim.still_scene import StillScene
from robocfg.viewer.frames import ArmFrames, arm_frames, box_corners, pad_boxes_ee
from robocfg.viewer.overlay import (
    ARROW_COLOR,
    AXIS_COLORS,
    COLLISION_COLOR,
    PAD_COLOR,
    Labels,
    draw_boxes,
    draw_frames,
    font,
)

PANEL = (560, 420)  # px per view
TAGS = {"base": "B", "ee_link": "E", "TCP": "T", "grasp": "G"}
VIEWS = (("front (camera on +x)", (1.0, 0.0, 0.3)), ("side (camera on −y)", (0.0, -1.0, 0.3)),
         ("top (camera on +z)", (0.0, 0.0, 1.0)))


@dataclass(frozen=True)
class Panel:
    """One rendered view: its title, camera and image."""

    title: str
    camera: CameraView
    image: Image.Image


def scene_frames(scene: StillScene, length: float) -> list[ArmFrames]:
    """Frames of every arm of every robot in ``scene`` at its current joint positions."""
    out = []
    for robot in scene.robots:
        for arm in robot.arms.values():
            out.append(arm_frames(arm.config, robot.link_pose, pad_boxes_ee(robot.checked, arm.config), length))
    return out


def collision_boxes(scene: StillScene) -> list[np.ndarray]:
    """(8, 3) corners of each robot link's collision bounding box (world-aligned, m)."""
    return [box_corners(lo, hi, np.eye(4)) for lo, hi in scene.robot_collision_aabbs()]


def _tags(frames: list[ArmFrames]) -> dict[str, str]:
    out = {}
    for arm in frames:
        prefix = "" if arm.arm == "arm" else arm.arm[:1].upper()
        for tri in arm.triads:
            kind = tri.label.split(": ")[-1].split(" ")[0]
            out[tri.label] = prefix + TAGS[kind]
    return out


def render_panel(scene: StillScene, title: str, camera: CameraView, frames: list[ArmFrames],
                 tags: dict[str, str] | None, axis_names: bool, boxes: list[np.ndarray]) -> Panel:
    """One view with the frames (and collision boxes, if any) drawn over it."""
    img = Image.fromarray(render(scene.client, camera, PANEL))

    def proj(points: np.ndarray):
        return project(points, scene.client, camera, PANEL)

    labels = Labels()
    draw_boxes(img, boxes, proj)
    draw_frames(img, frames, proj, labels, tags=tags, axis_names=axis_names)
    draw = ImageDraw.Draw(img)
    labels.draw(draw, *PANEL)
    draw.rectangle([0, 0, PANEL[0] - 1, 22], fill=(245, 245, 245))
    draw.text((6, 3), title, fill=(0, 0, 0), font=font(15))
    draw.rectangle([0, 0, PANEL[0] - 1, PANEL[1] - 1], outline=(120, 120, 120))
    return Panel(title, camera, img)


def tool_camera(scene: StillScene, frames: ArmFrames) -> CameraView:
    """Close-up of one arm's tool from across its closing axis, fitted to its frames and pads."""
    arm = next(a for r in scene.robots for a in r.arms.values() if a.config.name == frames.arm)
    T_ee = arm.ee_pose()
    tcp = frames.tcp()
    closing = frames.triads[3].pose[:3, 1]
    base = frames.triads[0].pose[:3, 3]
    look = facing_direction(tcp, closing, away_from=base)
    tips = [tri.pose[:3, 3] + tri.length * tri.pose[:3, a] for tri in frames.triads[1:] for a in range(3)]
    pts = [T_ee[:3, 3], tcp, *tips]
    pts += [c for pad in frames.pads for c in pad.corners]
    P = np.array(pts)
    return fit_camera(P.min(axis=0), P.max(axis=0), look, margin=1.25)


def robot_sheet(scene: StillScene, header: list[str], collision: bool = False) -> Image.Image:
    """The four-panel sheet with ``header`` lines on top and the legend below."""
    lo, hi = scene.aabb()
    size = float(np.max(hi - lo))
    length = float(np.clip(0.08 * size, 0.05, 0.4))
    frames = scene_frames(scene, length)
    tags = _tags(frames)
    boxes = collision_boxes(scene) if collision else []
    panels = [render_panel(scene, title, fit_camera(lo, hi, d), frames, tags, False, boxes) for title, d in VIEWS]
    first = frames[0]
    tcp_offset = scene.robots[0].arms[first.arm].config.tcp_offset
    close = scene_frames(scene, float(np.clip(0.6 * tcp_offset, 0.03, 0.3)))
    tool = replace(close[0], triads=close[0].triads[1:])  # the base is far away: not in the close-up
    panels.append(render_panel(scene, f"tool close-up ({first.arm})", tool_camera(scene, close[0]),
                               [tool], None, True, []))
    return _compose(panels, header, frames, tags, collision)


def _compose(panels: list[Panel], header: list[str], frames: list[ArmFrames], tags: dict[str, str],
             collision: bool) -> Image.Image:
    w, h = PANEL
    head_h, legend_h = 22 * len(header) + 12, 120
    sheet = Image.new("RGB", (2 * w, head_h + 2 * h + legend_h), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for k, line in enumerate(header):
        draw.text((10, 6 + 22 * k), line, fill=(0, 0, 0), font=font(17 if k == 0 else 14))
    for k, panel in enumerate(panels):
        sheet.paste(panel.image, ((k % 2) * w, head_h + (k // 2) * h))
    y0 = head_h + 2 * h + 8
    f = font(14)
    x = 10
    items = [(AXIS_COLORS[0], "x axis"), (AXIS_COLORS[1], "y axis"), (AXIS_COLORS[2], "z axis"),
             (ARROW_COLOR, "ee_axis: ee_link origin → TCP (tcp_offset)"), (PAD_COLOR, "finger pads (open)")]
    if collision:
        items.append((COLLISION_COLOR, "link collision bounding boxes"))
    for color, text in items:
        draw.line([(x, y0 + 9), (x + 26, y0 + 9)], fill=color, width=4)
        draw.text((x + 32, y0), text, fill=(0, 0, 0), font=f)
        x += 44 + int(draw.textlength(text, font=f))
    seen: dict[str, str] = {}
    for arm in frames:
        for tri in arm.triads:
            seen.setdefault(tags[tri.label], tri.label)
    lines = ["  ".join(f"{t} = {label}" for t, label in list(seen.items())[i:i + 4]) for i in range(0, len(seen), 4)]
    lines.append("grasp frame (GraspNet): x = approach (gripper → object), y = closing, z = x × y; "
                 "world_R_ee = world_R_grasp · R_ee_graspnet")
    for k, line in enumerate(lines):
        draw.text((10, y0 + 26 + 20 * k), line, fill=(0, 0, 0), font=f)
    return sheet
