"""One table from exception type to exit code and user message."""

from __future__ import annotations

from robocfg.errors import ConfigError, NotFound, RobocfgError, RunFailed

EXIT_OK, EXIT_RUN_FAILED, EXIT_INVALID = 0, 1, 2


def describe(exc: BaseException) -> tuple[int, str]:
    """(exit code, message lines) for an exception raised while running a command."""
    if isinstance(exc, ConfigError):
        return EXIT_INVALID, "\n".join(p.format() for p in exc.problems)
    if isinstance(exc, NotFound):
        return EXIT_INVALID, f"error: {exc}"
    if isinstance(exc, RunFailed):
        return EXIT_RUN_FAILED, f"failed: {exc.phase}: {exc.reason}"
    if isinstance(exc, RobocfgError):
        return EXIT_INVALID, f"error: {exc}"
    if isinstance(exc, KeyboardInterrupt):
        return 130, "interrupted"
    return EXIT_RUN_FAILED, f"internal error: {type(exc).__name__}: {exc} (run with --debug for the traceback)"
