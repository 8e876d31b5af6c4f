"""One table from exception type to exit code and user message."""

from __future__ import annotations

from robocfg.errors import ConfigError, NotFound, Problem, RobocfgError, RunFailed

EXIT_OK, EXIT_RUN_FAILED, EXIT_INVALID = 0, 1, 2

COMMAND_LINE = "<command line>"  # a problem's "file" when its ``path`` is the option itself


def describe(exc: BaseException) -> tuple[int, str]:
    """(exit code, message lines) for an exception raised while running a command."""
    if isinstance(exc, ConfigError):
        return EXIT_INVALID, "\n".join(format_problem(p) for p in exc.problems)
    if isinstance(exc, NotFound):
        return EXIT_INVALID, f"error: {exc}"
    if isinstance(exc, RunFailed):
        return EXIT_RUN_FAILED, f"failed: {exc.phase}: {exc.reason}"
    if isinstance(exc, RobocfgError):
        return EXIT_INVALID, f"error: {exc}"
    if isinstance(exc, KeyboardInterrupt):
        return 130, "interrupted"
    return EXIT_RUN_FAILED, f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)"


def format_problem(problem: Problem) -> str:
    """``FILE:LINE:COL: field: message``; a problem in a command-line value reads
    ``--set pick_place.lift_height: message`` or ``--robot pnda: message``."""
    # here, not at import: the YAML loader stays unloaded for --help (cli.app imports this module)
    from robocfg.config.overrides import OVERRIDE_SOURCE, ROBOT_OVERRIDE_SOURCE

    if problem.file == COMMAND_LINE and problem.path:
        return f"{problem.path}: {'' if problem.severity == 'error' else 'warning: '}{problem.message}"
    # problems in what was typed on the command line are named after the option that carried it
    option = {OVERRIDE_SOURCE: "--set", ROBOT_OVERRIDE_SOURCE: "--robot"}.get(problem.file)
    if option is None or problem.line is not None:
        return problem.format()
    prefix = "" if problem.severity == "error" else "warning: "
    return f"{option} {problem.path}: {prefix}{problem.message}" if problem.path else f"{option}: {prefix}{problem.message}"
