"""``robocfg view ROBOT_OR_TASK``: see the robot's frames — a PNG sheet (``--png``) or a browser viewer."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import console
from robocfg.cli.set_option import SetOpt, overrides


def view(
    target: Annotated[str, typer.Argument(help="Robot or task name, or a robot/task YAML path.")],
    png: Annotated[Path | None, typer.Option("--png", help="Write a sheet of views (front, side, top, tool) to this PNG and exit.", dir_okay=False)] = None,
    q: Annotated[str | None, typer.Option("--q", help="First arm's joint values (rad or m), comma/space separated; default home.")] = None,
    collision: Annotated[bool, typer.Option("--collision", help="Also draw the links' collision shapes.")] = False,
    host: Annotated[str, typer.Option("--host", help="Browser viewer: address to bind (0.0.0.0 exposes it).")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="Browser viewer: port.", min=1, max=65535)] = 8080,
    set_: SetOpt = None,
) -> None:
    """Show a robot, or a task's scene, with its frames. Base, ee_link, TCP and grasp frames,
    ee_axis and finger pads; in the browser, or as a PNG sheet with --png."""
    from robocfg.cli.ik import _parse_floats
    from robocfg.sim.quiet import quiet_import
    from robocfg.viewer.source import find_source

    quiet_import()  # the picture and the URDF preparation load pybullet: no build banner

    source = find_source(target, overrides(set_))
    joints = _parse_floats(q, "--q")
    if png is not None:
        from robocfg.viewer.picture import write_sheet

        out = write_sheet(source, png, q=joints, collision=collision)
        console().print(f"wrote {out}", markup=False)
        return
    from robocfg.viewer.server import serve

    serve(source, host=host, port=port, q=joints, on_ready=lambda url: console().print(
        f"robocfg view: open {url} in a browser (Ctrl-C to stop)", markup=False))
