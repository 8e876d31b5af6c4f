"""``robocfg run KIND``: one sub-command per registered task kind, made by one factory
(``robocfg.cli.run_command``). The kinds load when ``run`` itself is used, so ``robocfg --help``
and ``robocfg validate`` stay fast; ``robocfg run KIND --help`` loads that built-in kind's command
face only (``robocfg.runners.<kind>_command``: help and options, no episode code), ``robocfg run
KIND`` its runner when the command runs, ``robocfg run --help`` (the list) every runner."""

from __future__ import annotations

from typing import Any

import typer
from typer.core import TyperGroup


class _KindsGroup(TyperGroup):
    """The ``run`` group: its commands come from the task registry on first use."""

    _all_loaded = False

    def get_params(self, ctx: Any) -> Any:
        from robocfg.cli.flags import off_by_default

        return [off_by_default(p) for p in super().get_params(ctx)]  # --help

    def _add(self, kind: str, command: Any) -> Any:
        from robocfg.cli.help_style import polish
        from robocfg.cli.run_command import make_command
        from robocfg.engine.registry import command_name

        sub = typer.Typer(add_completion=False, rich_markup_mode=None)
        fn = make_command(command)
        sub.command(command_name(kind), help=fn.__doc__)(fn)
        cmd = self.commands[command_name(kind)] = typer.main.get_command(sub)
        polish(cmd)  # loaded after the root polished the tree
        return cmd

    def _commands(self) -> Any:
        if not self._all_loaded:
            from robocfg.engine.registry import command_name, registered

            kinds = registered()
            made = {name: self.commands.pop(name) for name in list(self.commands)}
            for kind, runner in kinds.items():  # in the registry's order, whichever were made first
                name = command_name(kind)
                if name in made:
                    self.commands[name] = made[name]
                else:
                    self._add(kind, runner)
            self._all_loaded = True
        return self.commands

    def list_commands(self, ctx: Any) -> list[str]:
        return list(self._commands())

    def get_command(self, ctx: Any, cmd_name: str) -> Any:
        from robocfg.engine.registry import builtin_kind

        if cmd_name in self.commands:
            return self.commands[cmd_name]
        kind = builtin_kind(cmd_name)  # a built-in kind: its command face alone (the runner loads to run)
        if kind is not None and not self._all_loaded:
            from robocfg.engine.registry import command_for

            return self._add(kind, command_for(kind))
        return self._commands().get(cmd_name)


run_app = typer.Typer(cls=_KindsGroup, help="Run a task in PyBullet (headless by default).", no_args_is_help=True)
