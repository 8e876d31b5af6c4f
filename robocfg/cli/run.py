"""``robocfg run COMMAND``: one sub-command per runner (each in its own cli module)."""

from __future__ import annotations

import typer

run_app = typer.Typer(help="Run a task in PyBullet (headless by default).", no_args_is_help=True)
