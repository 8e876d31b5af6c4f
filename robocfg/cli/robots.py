"""``robocfg robots``: the robots on the search path."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from robocfg.cli.common import JsonOpt, console, write_json


@dataclass(frozen=True)
class RobotEntry:
    """One robot file as listed: ``arms`` and ``grippers`` (one gripper type per arm, ``"none"``
    for an arm without one) in the order of the YAML's ``arms``; ``dof`` counts every arm's
    joints; ``problems``: how many errors an invalid YAML has (then the other fields are empty)."""

    name: str
    arms: list[str]
    dof: int
    grippers: list[str]
    description: str
    valid: bool
    problems: int
    source: str


def robots(json_path: JsonOpt = None) -> None:
    """List the robots on the search path. Searched: ./robots, $ROBOCFG_PATH, then the built-ins;
    each with its arms, DOF, gripper types, description and file."""
    from rich.table import Table

    from robocfg.config import catalog

    entries = [_entry(name, path) for name, path in catalog.available("robots").items()]
    table = Table(title="robots")
    for col in ("name", "arms", "DOF", "gripper", "description", "source"):
        table.add_column(col)
    for e in entries:
        table.add_row(e.name, ", ".join(e.arms), str(e.dof),
                      ", ".join(e.grippers) if e.valid else f"invalid ({e.problems} problems)",
                      e.description, e.source)
    console().print(table)
    write_json(json_path, [asdict(e) for e in entries])


def _entry(name: str, path) -> RobotEntry:
    from robocfg.checks import load_robot
    from robocfg.errors import ConfigError

    try:
        r = load_robot(path)
    except ConfigError as exc:
        return RobotEntry(name, [], 0, [], "", False, len(exc.problems), str(path))
    c = r.config
    return RobotEntry(name, [a.name for a in c.arms], sum(len(r.arm_joints(a)) for a in c.arms),
                      [a.gripper.type if a.gripper else "none" for a in c.arms], c.description, True, 0,
                      str(path))
