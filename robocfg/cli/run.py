"""``robocfg run COMMAND``: one sub-command per runner (each in its own cli module)."""

from __future__ import annotations

import typer

run_app = typer.Typer(help="Run a task in PyBullet (headless by default).", no_args_is_help=True)

from robocfg.cli import run_gripper  # noqa: E402

run_app.command("gripper")(run_gripper.gripper)
from robocfg.cli import run_trajectory  # noqa: E402

run_app.command("trajectory")(run_trajectory.run_trajectory)
from robocfg.cli import run_pick_place  # noqa: E402

run_app.command("pick-place")(run_pick_place.run_pick_place)
from robocfg.cli import run_follow_target  # noqa: E402

run_app.command("follow-target")(run_follow_target.run_follow_target)
from robocfg.cli import run_grasp  # noqa: E402

run_app.command("grasp")(run_grasp.run_grasp)
