"""``robocfg run KIND``: one sub-command per registered task kind, made by one factory
(``robocfg.cli.run_command``). The kinds load when ``run`` itself is used, so ``robocfg --help``
and ``robocfg validate`` stay fast."""

from __future__ import annotations

from typing import Any

import typer
from typer.core import TyperGroup


class _KindsGroup(TyperGroup):
    """The ``run`` group: its commands come from the task registry on first use."""

    _kinds_loaded = False

    def _commands(self) -> Any:
        if not self._kinds_loaded:
            from robocfg.cli.help_style import polish
            from robocfg.cli.run_command import make_command
            from robocfg.engine.registry import command_name, registered

            for kind, runner in registered().items():
                sub = typer.Typer(add_completion=False, rich_markup_mode=None)
                fn = make_command(runner)
                sub.command(command_name(kind), help=fn.__doc__)(fn)
                self.commands[command_name(kind)] = typer.main.get_command(sub)
                polish(self.commands[command_name(kind)])  # loaded after the root polished the tree
            self._kinds_loaded = True
        return self.commands

    def list_commands(self, ctx: Any) -> list[str]:
        return list(self._commands())

    def get_command(self, ctx: Any, cmd_name: str) -> Any:
        return self._commands().get(cmd_name)


run_app = typer.Typer(cls=_KindsGroup, help="Run a task in PyBullet (headless by default).", no_args_is_help=True)
