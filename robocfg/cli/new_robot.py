"""``robocfg new-robot URDF|PARTS.yaml [-o robots/NAME.yaml] [--force]``: draft a robot YAML, find a
home pose, validate it, list what remains."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import console


def new_robot(
    urdf: Annotated[Path, typer.Argument(help="The robot's URDF file, or a YAML with `urdf` and `attachments` (a composed robot).", dir_okay=False)],
    output: Annotated[Path | None, typer.Option("--output", "-o", help="Robot YAML to write (default: robots/<URDF stem>.yaml, the folder robocfg searches first).", dir_okay=False)] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite the output file if it exists.")] = False,
) -> None:
    """Draft a robot YAML from a URDF, or from a URDF plus attachments. Arm chain, gripper, EE
    link, TCP, R_ee_graspnet and a home pose found by IK with the tool down; the draft is validated
    and what a person must still check is printed. Exit 1 if the draft does not validate."""
    from robocfg.assets.draft_yaml import render_yaml
    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.errors import ConfigError, RobocfgError

    if not urdf.is_file():
        raise RobocfgError(f"URDF not found: {urdf}")
    name = re.sub(r"[^A-Za-z0-9_\-]", "_", (output.stem if output else urdf.stem))
    out_path = output or Path("robots") / f"{name}.yaml"
    if out_path.resolve().is_relative_to(catalog.BUILTIN_DIR):
        raise typer.BadParameter(f"{str(out_path)!r} is inside the package's built-in robots; write your robot "
                                 "to ./robots (found by name from there) or any other folder", param_hint="--output")
    if out_path.exists() and not force:
        raise RobocfgError(f"{out_path} exists; pass --force to overwrite it")
    draft = _draft(urdf, name, out_path.parent)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    out_path.write_text(render_yaml(draft))
    home_note = _find_home(out_path, draft)
    if home_note is None:
        draft = replace(draft, home_found=True)
        out_path.write_text(render_yaml(draft))
    else:
        draft.notes.append(home_note)
    out = console()
    g = draft.gripper
    out.print(f"wrote {out_path}: arm {len(draft.arm_joints)} joints ({draft.arm_joints[0]} … {draft.arm_joints[-1]}), "
              f"ee_link {draft.ee_link}, TCP {draft.tcp_offset} m along +{draft.ee_axis}, "
              f"gripper {g.kind + ' ' + str(g.joints) if g else 'none found'}")
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


def _draft(source: Path, name: str, out_dir: Path):
    """The RobotDraft of a URDF, or of a YAML naming ``urdf`` + ``attachments``."""
    from robocfg.assets.compose import CompositionError
    from robocfg.assets.draft import draft_composed, draft_robot
    from robocfg.assets.paths import UnresolvedPath
    from robocfg.assets.urdf import UrdfParseError
    from robocfg.assets.urdf_xml import parse_urdf
    from robocfg.config.load import load_yaml
    from robocfg.config.robot import RobotSource
    from robocfg.config.validation import validate_document
    from robocfg.errors import ConfigError, Problem, RobocfgError

    try:
        if source.suffix.lower() in (".yaml", ".yml"):
            doc = load_yaml(source)
            return draft_composed(source, validate_document(doc, RobotSource), name, out_dir)
        return draft_robot(parse_urdf(source), name, out_dir)
    except UrdfParseError as exc:
        raise ConfigError([Problem(str(source), exc.line, None, "", f"URDF does not parse: {exc}")]) from None
    except CompositionError as exc:
        raise RobocfgError(f"{source}: cannot compose the robot: " + "; ".join(p.message for p in exc.problems)) from None
    except (UnresolvedPath, ValueError) as exc:
        raise RobocfgError(f"{source}: {exc}") from None


def _find_home(path: Path, draft) -> str | None:
    """Put an IK home (tool down over the workspace) into ``draft``; a note when none was found."""
    from robocfg.checks import load_robot
    from robocfg.errors import ConfigError, RobocfgError
    from robocfg.kinematics.home import find_home
    from robocfg.kinematics.model import KinematicModel

    try:
        model = KinematicModel.from_robot(load_robot(path))
    except (ConfigError, RobocfgError) as exc:
        return f"home: 0 or mid-limits per joint (no IK home: the draft does not load yet: {str(exc).splitlines()[0]})"
    q = find_home(model)
    if q is None:
        return "home: 0 or mid-limits per joint — no pose with the tool pointing down in front of the robot was reachable; pick one"
    draft.home = [round(float(v), 4) for v in q]
    return None
