"""What a user may set about a recording (``--camera``, ``--size``, ``--fps`` of ``robocfg run``):
each overrides what the run would choose (a camera fitted to the scene, 320×240, the kind's rate).

``--camera yaw,pitch,distance,tx,ty,tz``: an orbit camera as in PyBullet's debug view: yaw and
pitch in degrees, distance in m, looking at the target point (tx, ty, tz) in the world frame (m).
``--size WxH`` in pixels; ``--fps`` frames per second of simulated time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

MIN_SIZE, MAX_SIZE = 32, 1920  # pixels per side
MAX_FPS = 120.0


@dataclass(frozen=True)
class OrbitCamera:
    """Yaw and pitch (deg), distance (m) and target (world, m) of an orbit camera."""

    yaw_deg: float
    pitch_deg: float
    distance: float
    target: tuple[float, float, float]


@dataclass(frozen=True)
class RecordSettings:
    """Overrides for a recording; None keeps the run's own choice."""

    camera: OrbitCamera | None = None
    size: tuple[int, int] | None = None  # (W, H) pixels
    fps: float | None = None  # frames per second of simulated time


def parse_camera(text: str) -> OrbitCamera:
    """``yaw,pitch,distance,tx,ty,tz`` → OrbitCamera; ValueError says what is wrong."""
    parts = [s for s in text.replace(" ", ",").split(",") if s]
    if len(parts) != 6:
        raise ValueError(f"{text!r}: give six numbers yaw,pitch,distance,tx,ty,tz (deg, deg, m, m, m, m)")
    try:
        yaw, pitch, dist, tx, ty, tz = (float(s) for s in parts)
    except ValueError:
        raise ValueError(f"{text!r}: six numbers yaw,pitch,distance,tx,ty,tz expected") from None
    if not all(math.isfinite(v) for v in (yaw, pitch, dist, tx, ty, tz)):
        raise ValueError(f"{text!r}: numbers must be finite")
    if dist <= 0:
        raise ValueError(f"{text!r}: distance must be > 0 m, got {dist:g}")
    return OrbitCamera(yaw, pitch, dist, (tx, ty, tz))


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` → (W, H) pixels, each in [MIN_SIZE, MAX_SIZE]; ValueError says what is wrong."""
    parts = text.lower().replace("×", "x").split("x")
    try:
        w, h = (int(s) for s in parts)
    except ValueError:
        raise ValueError(f"{text!r}: give the size as WxH in pixels, e.g. 480x360") from None
    if not (MIN_SIZE <= w <= MAX_SIZE and MIN_SIZE <= h <= MAX_SIZE):
        raise ValueError(f"{text!r}: width and height must be {MIN_SIZE}..{MAX_SIZE} pixels")
    return w, h
