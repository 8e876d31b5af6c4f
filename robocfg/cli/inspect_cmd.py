"""``robocfg inspect ROBOT_OR_URDF``: links, joints with DOF and PyBullet indices, EE candidates."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import JsonOpt, console, write_json


def inspect(
    target: Annotated[str, typer.Argument(help="Robot name, robot YAML, or a URDF: a path, pybullet_data://REL, "
                                                "airo_models://NAME (URIs as in a robot YAML's urdf).")],
    json_path: JsonOpt = None,
) -> None:
    """Print a robot's joint table and EE-link candidates. Each joint with its DOF index, PyBullet
    index, type, limits and mimic."""
    from rich.table import Table

    from robocfg.assets.inspection import inspect_urdf
    from robocfg.assets.urdf import UrdfParseError
    from robocfg.assets.urdf_xml import parse_urdf
    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.errors import ConfigError

    robot = None
    if target.endswith(".urdf") or "://" in target:
        urdf_path = _resolve_urdf(target)
        try:
            urdf = parse_urdf(urdf_path)
        except UrdfParseError as exc:
            raise ConfigError([_urdf_problem(urdf_path, exc)]) from None
    else:
        robot = load_robot(catalog.find("robots", target))
        urdf_path, urdf = robot.urdf_path, robot.urdf
    info = inspect_urdf(urdf)
    out = console()
    out.print(f"[bold]{urdf.name}[/bold]  {urdf_path}")
    out.print(f"links ({len(urdf.links)}): " + ", ".join(urdf.links))
    table = Table(title="joints")
    for col in ("DOF", "pybullet", "name", "type", "parent → child", "lower", "upper", "velocity", "mimic"):
        table.add_column(col)
    for j in info.joints:
        table.add_row("" if j.dof_index is None else str(j.dof_index), str(j.pybullet_index), j.name, j.type,
                      f"{j.parent} → {j.child}", _num(j.lower, j.movable), _num(j.upper, j.movable),
                      _num(j.velocity, j.movable), j.mimic or "")
    out.print(table)
    out.print("EE-link candidates: " + ", ".join(info.ee_candidates))
    payload = {"urdf": str(urdf_path), "joints": [j.__dict__ for j in info.joints], "ee_candidates": info.ee_candidates}
    if robot is not None:
        for arm in robot.config.arms:
            out.print(f"arm [bold]{arm.name}[/bold]: ee_link {arm.ee_link}, TCP {arm.tcp_offset} m along +{arm.ee_axis}, "
                      f"gripper {arm.gripper.type if arm.gripper else 'none'}")
        payload["arms"] = [a.model_dump() for a in robot.config.arms]
    write_json(json_path, payload)


def _resolve_urdf(uri: str) -> Path:
    """The URDF file a URI names; a plain path as given (problems are reported at that name)."""
    from robocfg.assets.paths import Resolver, UnresolvedPath
    from robocfg.errors import RobocfgError

    if "://" not in uri:
        return Path(uri)
    try:
        return Resolver(Path.cwd()).urdf(uri)
    except UnresolvedPath as exc:
        raise RobocfgError(str(exc)) from None


def _num(v: float, show: bool) -> str:
    return f"{v:.4f}" if show else ""


def _urdf_problem(path: Path, exc: Exception):
    from robocfg.errors import Problem

    return Problem(str(path), getattr(exc, "line", None), None, "", f"URDF does not parse: {exc}")
