"""Top-level CLI: wires the command modules and maps exceptions to exit codes. No logic here."""

from __future__ import annotations

import os
import sys

import typer

from robocfg.cli import inspect_cmd, robots, run, schema, validate

app = typer.Typer(
    name="robocfg",
    help="Robots and tasks from validated YAML, run headless in PyBullet.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show Python tracebacks on errors."),
    version: bool = typer.Option(False, "--version", help="Print the version and exit."),
) -> None:
    if debug:
        os.environ["ROBOCFG_DEBUG"] = "1"
    if version:
        from robocfg import __version__

        typer.echo(__version__)
        raise typer.Exit(0)


app.command("validate")(validate.validate)
app.command("robots")(robots.robots)
app.command("inspect")(inspect_cmd.inspect)
app.command("schema")(schema.schema)
app.add_typer(run.run_app, name="run")


def main() -> None:
    """Console-script entry point."""
    from robocfg.cli.common import debug_enabled
    from robocfg.cli.errors import describe

    if "--debug" in sys.argv[1:]:
        os.environ["ROBOCFG_DEBUG"] = "1"
    try:
        rv = app(standalone_mode=False)
        sys.exit(rv if isinstance(rv, int) else 0)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except SystemExit:
        raise
    except BaseException as exc:
        import click

        if isinstance(exc, click.exceptions.Abort):
            sys.exit(130)
        if isinstance(exc, click.ClickException):
            exc.show()
            sys.exit(2)
        if debug_enabled():
            raise
        code, message = describe(exc)
        print(message, file=sys.stderr)
        sys.exit(code)
