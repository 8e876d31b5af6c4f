"""One root exception with subclasses that carry context.

The CLI maps each type to an exit code and a message (``robocfg/cli/errors.py``):
``ConfigError`` → exit 2 (invalid input), ``RunFailed`` → exit 1 (a run that could not succeed).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

Severity = Literal["error", "warning"]


@dataclass(frozen=True)
class Problem:
    """One finding about a user file, printed as ``FILE:LINE:COL: path.to.field: message``."""

    file: str
    line: int | None
    col: int | None
    path: str
    message: str
    severity: Severity = "error"

    def format(self) -> str:
        where = self.file
        if self.line is not None:
            where += f":{self.line}"
            if self.col is not None:
                where += f":{self.col}"
        prefix = "" if self.severity == "error" else "warning: "
        field_part = f" {self.path}:" if self.path else ""
        return f"{where}:{field_part} {prefix}{self.message}"


class RobocfgError(Exception):
    """Root of every error robocfg raises on purpose."""


@dataclass
class ConfigError(RobocfgError):
    """Invalid user input: one or more problems, each with file and line."""

    problems: list[Problem] = field(default_factory=list)

    def __str__(self) -> str:
        return "\n".join(p.format() for p in self.problems)


class NotFound(RobocfgError):
    """A name (robot, task, frame, backend...) that does not exist; lists the names that do."""

    def __init__(self, kind: str, name: str, known: list[str]):
        from robocfg.suggest import did_you_mean

        self.kind, self.name, self.known = kind, name, list(known)
        hint = did_you_mean(name, known)
        listing = ", ".join(sorted(known)) if known else "none"
        super().__init__(f"unknown {kind} {name!r}{hint}; known: {listing}")


class PhaseFailed(RobocfgError):
    """A phase of an episode could not be completed: its ``phase`` name (``approach``, ``lift``,
    ``perception``...) and a one-line ``reason`` (``IK did not converge, residual 4.2 mm``).
    The one (phase, reason) error: moves, episodes and whole runs raise it or a subclass."""

    def __init__(self, phase: str, reason: str):
        self.phase, self.reason = phase, reason
        super().__init__(f"{phase}: {reason}")


class RunFailed(PhaseFailed):
    """A whole run that could not succeed (exit 1); ``report``: what it measured before failing."""

    def __init__(self, phase: str, reason: str, report: object | None = None):
        super().__init__(phase, reason)
        self.report = report


class RunInterrupted(PhaseFailed):
    """The run was asked to stop (SIGINT/SIGTERM) in the middle of ``phase``; the runner ends it
    with its report marked ``interrupted``."""

    def __init__(self, phase: str, signal_name: str = "a stop request"):
        super().__init__(phase, f"interrupted by {signal_name}")


class PhysicsDiverged(RunFailed):
    """NaN or exploding velocities in the simulation."""

    def __init__(self, t: float, detail: str, report: object | None = None):
        super().__init__("physics", f"physics diverged at t = {t:.3f} s ({detail})", report)
