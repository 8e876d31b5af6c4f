"""``robocfg new-robot URDF [-o robots/NAME.yaml] [--force]``: draft a robot YAML, validate it, list what remains."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import console


def new_robot(
    urdf: Annotated[Path, typer.Argument(help="The robot's URDF file.", dir_okay=False)],
    output: Annotated[Path | None, typer.Option("--output", "-o", help="Robot YAML to write (default: robots/<URDF stem>.yaml).", dir_okay=False)] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite the output file if it exists.")] = False,
) -> None:
    """Write a draft robot YAML from a URDF (arm chain, gripper, EE link, TCP, R_ee_graspnet, home),
    validate it and print what a person must still check. Exit 1 if the draft does not validate."""
    from robocfg.assets.draft import draft_robot, render_yaml
    from robocfg.assets.urdf import UrdfParseError, parse_urdf
    from robocfg.checks import load_robot
    from robocfg.errors import ConfigError, Problem, RobocfgError

    if not urdf.is_file():
        raise RobocfgError(f"URDF not found: {urdf}")
    name = re.sub(r"[^A-Za-z0-9_\-]", "_", (output.stem if output else urdf.stem))
    out_path = output or Path("robots") / f"{name}.yaml"
    if out_path.exists() and not force:
        raise RobocfgError(f"{out_path} exists; pass --force to overwrite it")
    try:
        parsed = parse_urdf(urdf)
    except UrdfParseError as exc:
        raise ConfigError([Problem(str(urdf), exc.line, None, "", f"URDF does not parse: {exc}")]) from None
    try:
        draft = draft_robot(parsed, name, out_path.parent)
    except ValueError as exc:
        raise RobocfgError(str(exc)) from None
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(render_yaml(draft))
    out = console()
    out.print(f"wrote {out_path}: arm {len(draft.arm_joints)} joints ({draft.arm_joints[0]} … {draft.arm_joints[-1]}), "
              f"ee_link {draft.ee_link}, TCP {draft.tcp_offset} m along +{draft.ee_axis}, "
              f"gripper {'parallel ' + str(draft.gripper.joints) if draft.gripper else 'none found'}")
    try:
        robot = load_robot(out_path)
        problems, ok = robot.warnings, True
    except ConfigError as exc:
        problems, ok = exc.problems, False
    for pr in problems:
        out.print(pr.format())
    out.print("validate: " + ("ok" if ok else "the draft does not validate yet (errors above)")
              + (f", {len(robot.warnings)} warning(s)" if ok and robot.warnings else ""))
    out.print("still to check (lines marked CHECK in the file):")
    for note in draft.notes:
        out.print(f"  - {note}")
    if not ok:
        raise typer.Exit(1)
