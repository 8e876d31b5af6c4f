"""Top-level CLI: wires the command modules and maps exceptions to exit codes. No logic here."""

from __future__ import annotations

import sys

import typer
import typer.core

from robocfg.cli import (
    bench,
    dataset,
    ik,
    inspect_cmd,
    interop,
    new_robot,
    robots,
    run,
    schema,
    tasks,
    validate,
    view,
)


class _RootGroup(typer.core.TyperGroup):
    """The ``robocfg`` group: once typer has built the whole command tree, every command's help
    gets readable placeholders and whole summaries (``robocfg.cli.help_style``); its flags left
    off read ``False`` (``robocfg.cli.flags``)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        from robocfg.cli.help_style import polish

        polish(self)

    def get_params(self, ctx):
        from robocfg.cli.flags import off_by_default

        return [off_by_default(p) for p in super().get_params(ctx)]  # --help, --install-completion...


app = typer.Typer(
    name="robocfg",
    help="Robots and tasks from validated YAML, run headless in PyBullet.",
    cls=_RootGroup,
    no_args_is_help=True,
    add_completion=True,  # --install-completion / --show-completion for bash, zsh, fish, PowerShell
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain help: rendering it with rich costs ~0.15 s of imports on every --help
    context_settings={"help_option_names": ["-h", "--help"], "max_content_width": 100},
)


def _print_version(value: bool) -> None:
    if value:
        from robocfg import __version__

        typer.echo(__version__)
        raise typer.Exit(0)


@app.callback()
def _root(
    debug: bool = typer.Option(False, "--debug", help="Show Python tracebacks on errors."),
    version: bool = typer.Option(False, "--version", help="Print the version and exit.",
                                 callback=_print_version, is_eager=True),
) -> None:
    from robocfg.cli import common

    common.set_debug(debug)
    common._stdout_taken = False  # set again by ``--json -`` while this command line is parsed


app.command("validate")(validate.validate)
app.command("robots")(robots.robots)
app.command("tasks")(tasks.tasks)
app.command("inspect")(inspect_cmd.inspect)
app.command("new-robot")(new_robot.new_robot)
app.command("schema")(schema.schema)
app.add_typer(run.run_app, name="run")
app.command("ik")(ik.ik)
app.add_typer(bench.bench_app, name="bench")
app.add_typer(interop.import_app, name="import")
app.add_typer(interop.export_app, name="export")
app.command("view")(view.view)
app.add_typer(dataset.dataset_app, name="dataset")


def main() -> None:
    """Console-script entry point."""
    from robocfg import collector
    from robocfg.cli.common import set_debug
    from robocfg.cli.process import single_math_thread, skip_final_collection
    from robocfg.config.pydantic_plugins import deferring

    collector.pause()  # no collections during the start: resumed once a world is built (robocfg.collector)
    single_math_thread()  # before numpy loads (robocfg.cli.process)
    skip_final_collection()  # before any command registers its own atexit handlers
    set_debug("--debug" in sys.argv[1:])
    # pydantic's plugin loader, whoever imports it first (typer's parameter adapters do, before
    # robocfg's models), without importlib.metadata (robocfg.config.pydantic_plugins)
    with deferring():
        _run()


def _run() -> None:
    """The command line run, its exceptions mapped to exit codes and messages."""
    from robocfg import collector
    from robocfg.cli.common import debug_enabled
    from robocfg.cli.errors import describe

    try:
        rv = app(standalone_mode=False)
        sys.exit(rv if isinstance(rv, int) else 0)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except SystemExit:
        raise
    except BaseException as exc:
        abort, usage = _cli_exception_types()
        if isinstance(exc, abort):
            sys.exit(130)
        if isinstance(exc, usage):
            exc.show()  # type: ignore[attr-defined]
            code = getattr(exc, "exit_code", 2)
            sys.exit(code if isinstance(code, int) and code != 1 else 2)
        if debug_enabled():
            raise
        code, message = describe(exc)
        print(message, file=sys.stderr)
        sys.exit(code)
    finally:
        collector.restore()  # a program or a test calling main() gets its thresholds back


def _cli_exception_types() -> tuple[tuple[type, ...], tuple[type, ...]]:
    """(abort, usage-error) exception classes: typer ≥ 0.16 vendors click as ``typer._click``;
    older typer versions raise click's own classes."""
    abort: list[type] = [typer.Abort]
    usage: list[type] = [t for t in (getattr(typer, "TyperException", None),) if t is not None]
    try:
        import click
    except ImportError:
        pass
    else:
        abort.append(click.exceptions.Abort)
        usage.append(click.ClickException)
    return tuple(abort), tuple(usage)
