"""``robocfg robots``: the robots on the search path."""

from __future__ import annotations

from robocfg.cli.common import JsonOpt, console, write_json


def robots(json_path: JsonOpt = None) -> None:
    """List robots found in ./robots, $ROBOCFG_PATH and the built-ins, with DOF and gripper type."""
    from rich.table import Table

    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.errors import ConfigError

    table = Table(title="robots")
    for col in ("name", "arms", "DOF", "gripper", "source"):
        table.add_column(col)
    rows = []
    for name, path in catalog.available("robots").items():
        try:
            r = load_robot(path)
            arms = [a.name for a in r.config.arms]
            dof = sum(len(r.arm_joints(a)) for a in r.config.arms)
            grippers = [a.gripper.type if a.gripper else "none" for a in r.config.arms]
            problems = 0
        except ConfigError as exc:
            arms, dof, grippers, problems = [], 0, [], len(exc.problems)
        # one gripper type per arm, in the order of ``arms``; ``problems``: errors in an invalid YAML
        rows.append({"name": name, "arms": arms, "dof": dof, "grippers": grippers, "valid": problems == 0,
                     "problems": problems, "source": str(path)})
        table.add_row(name, ",".join(arms), str(dof),
                      ",".join(grippers) if not problems else f"invalid ({problems} problems)", str(path))
    console().print(table)
    write_json(json_path, rows)
