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
    run: Annotated[str | None, typer.Option("--run", metavar="KIND", help="Browser viewer of a task: simulate one episode headless first (pick-place, grasp), then play it back in the page (time slider, play/pause).")] = None,
    seed: Annotated[int | None, typer.Option("--seed", min=0, help="With --run: the run's seed (default: the task's).")] = None,
    episode: Annotated[int, typer.Option("--episode", min=0, help="With --run: which episode to play.")] = 0,
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
    playback = None
    if run is not None:
        playback = _record(source, run, seed, episode)
    from robocfg.viewer.server import serve

    serve(source, host=host, port=port, q=joints, playback=playback, on_ready=lambda url: console().print(
        f"robocfg view: open {url} in a browser (Ctrl-C to stop)", markup=False))


def _record(source, kind: str, seed: int | None, episode: int):
    """The playback of one episode of the task ``source`` (``kind`` must be the task's kind)."""
    from robocfg.viewer.playback import record_run

    if source.kind != "task":
        raise typer.BadParameter(f"--run plays a task; {source.path.name} is a robot YAML", param_hint="--run")
    task = source.load()
    wanted = kind.replace("-", "_")
    if wanted != task.config.task:
        raise typer.BadParameter(f"{source.path.name} is a {task.config.task!r} task, not {wanted!r}",
                                 param_hint="--run")
    console(stderr=True).print(f"simulating episode {episode} of {source.path.name} ...", markup=False)
    return record_run(task, seed=seed, episode=episode)
