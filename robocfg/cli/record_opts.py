"""``--camera``, ``--size`` and ``--fps`` of every ``robocfg run <kind>``: how ``--record`` films.

Checked before anything is simulated (a bad value exits 2 naming the option), then gathered into
the RecordSettings the recorder applies over the run's own choice of camera, size and rate.
"""

from __future__ import annotations

from typing import Annotated

import typer

from robocfg.sim.record_settings import MAX_FPS, RecordSettings, parse_camera, parse_size

CameraOpt = Annotated[str | None, typer.Option(
    "--camera", metavar="YAW,PITCH,DIST,TX,TY,TZ",
    help="--record camera: yaw and pitch (deg), distance (m), target point x,y,z (world, m); "
         "default: fitted to the scene.")]
SizeOpt = Annotated[str | None, typer.Option(
    "--size", metavar="WxH", help="--record image size in pixels (default 320x240).")]
FpsOpt = Annotated[float | None, typer.Option(
    "--fps", min=0.5, max=MAX_FPS, help="--record frames per second of simulated time (default: the kind's, 10-15).")]


def record_settings(camera: str | None, size: str | None, fps: float | None, recording: bool) -> RecordSettings | None:
    """The settings, or None when none is given; exit 2 on a bad value or when one is given
    without --record."""
    given = [name for name, v in (("--camera", camera), ("--size", size), ("--fps", fps)) if v is not None]
    if not given:
        return None
    if not recording:
        raise typer.BadParameter(f"{', '.join(given)} set how --record films: add --record PATH", param_hint=given[0])
    try:
        cam = None if camera is None else parse_camera(camera)
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint="--camera") from None
    try:
        wh = None if size is None else parse_size(size)
    except ValueError as exc:
        raise typer.BadParameter(str(exc), param_hint="--size") from None
    return RecordSettings(camera=cam, size=wh, fps=fps)
