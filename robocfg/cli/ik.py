"""``robocfg ik ROBOT --position X Y Z [--euler-deg R P Y | --quat-xyzw X Y Z W]``: solve one IK query.

Prints the joint solution and the residuals; exit 1 (RunFailed) if the solver did not converge.
Without an orientation the query is position-only. Poses are in the robot's base frame (the
robot is not mounted anywhere here).
"""

from __future__ import annotations

from typing import Annotated

import typer

from robocfg.cli.common import JsonOpt, QuietOpt, console, write_json


def _parse_floats(text: str | None, what: str) -> list[float] | None:
    from robocfg.errors import ConfigError, Problem

    if text is None:
        return None
    try:
        return [float(v) for v in text.replace(",", " ").split()]
    except ValueError:
        raise ConfigError([Problem("<command line>", None, None, what, f"expected numbers, got {text!r}")]) from None


def _option_of(loc: tuple, message: str) -> str:
    """The option(s) a pose problem came from: ``("euler_deg", 1)`` → ``--euler-deg``; a problem
    of the whole pose names the fields its message mentions."""
    fields = [str(x) for x in loc if isinstance(x, str)]
    fields = fields[:1] or [f for f in ("position", "euler_deg", "quat_xyzw") if f in message]
    return "/".join(f"--{f.replace('_', '-')}" for f in fields) or "--position"


def _target(position: tuple[float, float, float], euler_deg: tuple[float, float, float] | None,
            quat_xyzw: tuple[float, float, float, float] | None):
    """4x4 target from the options, validated by the same Pose model the YAML files use."""
    from pydantic import ValidationError

    from robocfg.config.types import Pose
    from robocfg.errors import ConfigError, Problem

    try:
        pose = Pose(position=list(position), euler_deg=list(euler_deg) if euler_deg else None,
                    quat_xyzw=list(quat_xyzw) if quat_xyzw else None)
    except ValidationError as exc:
        raise ConfigError([Problem("<command line>", None, None, _option_of(e["loc"], e["msg"]),
                                   e["msg"].removeprefix("Value error, ")) for e in exc.errors()]) from None
    from robocfg.geometry import pose_matrix

    return pose_matrix(pose)


def ik(
    robot: Annotated[str, typer.Argument(help="Robot name or robot YAML path.")],
    position: Annotated[tuple[float, float, float], typer.Option("--position", help="Target position X Y Z (m).")],
    euler_deg: Annotated[tuple[float, float, float] | None, typer.Option("--euler-deg", metavar="R P Y", help="Roll pitch yaw (deg), R = Rz·Ry·Rx.")] = None,
    quat_xyzw: Annotated[tuple[float, float, float, float] | None, typer.Option("--quat-xyzw", help="Unit quaternion x y z w.")] = None,
    frame: Annotated[str, typer.Option("--frame", help="tcp, ee (the ee_link) or any link name.")] = "tcp",
    backend: Annotated[str | None, typer.Option("--backend", help="IK backend (default: the robot YAML's ik_backend).")] = None,
    seed_q: Annotated[str | None, typer.Option("--seed-q", help="Seed joint values (rad), comma/space separated; default home.")] = None,
    arm: Annotated[str | None, typer.Option("--arm", help="Arm name (default: the first arm).")] = None,
    budget_ms: Annotated[float, typer.Option("--budget-ms", help="Time budget (ms).", min=0.1)] = 50.0,
    json_path: JsonOpt = None,
    quiet: QuietOpt = False,
) -> None:
    """Solve inverse kinematics for one target pose. Exit 1 if it does not converge."""
    import math

    from robocfg.checks import load_robot
    from robocfg.config import catalog
    from robocfg.engine.runner import check_arm_option
    from robocfg.errors import RunFailed
    from robocfg.kinematics.model import KinematicModel

    T = _target(position, euler_deg, quat_xyzw)
    position_only = euler_deg is None and quat_xyzw is None
    checked = load_robot(catalog.find("robots", robot))
    check_arm_option(checked.config, arm)
    model = KinematicModel.from_robot(checked, arm=arm)
    seed = _parse_floats(seed_q, "--seed-q")
    res = model.ik(T, seed_q=seed, frame=frame, backend=backend, time_budget=budget_ms / 1000.0,
                   position_only=position_only)
    payload = {
        "robot": checked.config.name, "frame": frame, "target": T.tolist(), "position_only": position_only,
        "joints": dict(zip(model.joint_names, res.q.tolist(), strict=True)), **res.to_dict(),
    }
    write_json(json_path, payload)
    out = console()
    if not quiet:
        from rich.table import Table

        table = Table(title=f"{checked.config.name}: IK for {frame} ({res.backend})")
        for col in ("joint", "rad", "deg", "limits (rad)"):
            table.add_column(col)
        for k, name in enumerate(model.joint_names):
            v = float(res.q[k])
            mark = " (at limit)" if name in res.joints_at_limit else ""
            table.add_row(name, f"{v:.6f}", f"{math.degrees(v):.3f}", f"[{model.lower[k]:.4f}, {model.upper[k]:.4f}]{mark}")
        out.print(table)
    mode = " (position only)" if position_only else ""
    out.print(f"{'converged' if res.converged else 'NOT converged'}{mode}: position error {res.pos_err * 1e3:.4g} mm, "
              f"rotation error {math.degrees(res.rot_err):.4g}°, {res.iterations} iterations, "
              f"{res.restarts} restarts, {res.time_s * 1e3:.2f} ms")
    if quiet:
        out.print(" ".join(f"{v:.6f}" for v in res.q.tolist()))
    if not res.converged:
        raise RunFailed("ik", f"did not converge within {budget_ms:g} ms: best residual "
                              f"{res.pos_err * 1e3:.3g} mm, {math.degrees(res.rot_err):.3g}°")

