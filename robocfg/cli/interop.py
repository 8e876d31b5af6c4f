"""``robocfg import interndata`` and ``robocfg export interndata``: InternDataEngine robot configs."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import console

import_app = typer.Typer(help="Convert another tool's robot config into a robocfg robot YAML.", no_args_is_help=True)
export_app = typer.Typer(help="Write a robocfg robot as another tool's robot config.", no_args_is_help=True)

OutputOpt = Annotated[Path, typer.Option("--output", "-o", help="File to write.", dir_okay=False)]
ForceOpt = Annotated[bool, typer.Option("--force", help="Overwrite the output file if it exists.")]


def _refuse_overwrite(path: Path, force: bool) -> None:
    from robocfg.errors import RobocfgError

    if path.exists() and not force:
        raise RobocfgError(f"{path} exists; pass --force to overwrite it")


@import_app.command("interndata")
def import_interndata(
    their: Annotated[Path, typer.Argument(help="InternDataEngine robot YAML.", dir_okay=False)],
    output: OutputOpt,
    urdf: Annotated[str | None, typer.Option("--urdf", help="The URDF its USD was made from (path or pybullet_data:// URI); "
                                                    "optional when the file has a robocfg: block.")] = None,
    force: ForceOpt = False,
) -> None:
    """Convert an InternDataEngine robot config into a robot YAML. Lists what was dropped and why,
    and validates the result. Errors point at lines of THEIR file. Exit 0 written, 2 invalid."""
    from robocfg.interop.interndata_import import import_interndata as convert

    _refuse_overwrite(output, force)
    result = convert(their, output, urdf)
    out, err = console(), console(stderr=True)
    for w in result.warnings:
        err.print(w.format(), markup=False)
    for d in result.dropped:
        out.print(f"dropped {d.key}: {d.why}", markup=False)
    for note in result.notes:
        out.print(f"derived {note}", markup=False)
    arms = ", ".join(f"{a.name} ({len(result.robot.arm_joints(a))} joints, ee_link {a.ee_link})" for a in result.robot.config.arms)
    out.print(f"wrote {output}: arms {arms}; validate: ok"
              + (f", {len(result.warnings)} warning(s)" if result.warnings else ""), markup=False)


@export_app.command("interndata")
def export_interndata(
    robot: Annotated[str, typer.Argument(help="Robot YAML file or built-in robot name.")],
    output: OutputOpt,
    force: ForceOpt = False,
) -> None:
    """Write a robocfg robot as an InternDataEngine robot config. The robot is validated first; the
    items of their checklist that robocfg verified are marked in a comment block. Exit 0 written, 2 invalid robot."""
    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.interop.interndata_export import export_interndata as convert

    _refuse_overwrite(output, force)
    checked = load_robot(catalog.find("robots", robot))
    exported = convert(checked, output)
    output.parent.mkdir(parents=True, exist_ok=True)
    tmp = output.with_name(f".{output.name}.tmp")
    tmp.write_text(exported.text, encoding="utf-8")
    tmp.replace(output)
    console().print(f"wrote {output}: {len(checked.config.arms)} arm(s); robocfg-only fields in its robocfg: block: "
                    f"{', '.join(exported.block_keys) or 'none'}", markup=False)
