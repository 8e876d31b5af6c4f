"""Printing a run's report: the full view (tables, failures, status) or, with ``-q``, one line
plus one line per distinct failure reason. The report decides what is shown; this only renders."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from robocfg.cli.common import console, key_value_table


def _is_problem(line: str) -> bool:
    """A warning formatted as a problem (``FILE:LINE:COL: field: warning: message``) says so itself."""
    return ": warning: " in line


def _warning(line: str) -> str:
    return line if _is_problem(line) else f"warning: {line}"


_STATUS_HEADS = ("ok", "failed", "FAILED", "not reached")


def summary_line(report: Any, timing: Any) -> str:
    """The report's one line; an interrupted run's says ``interrupted`` where the line would say
    ``ok`` or ``failed`` of the episodes that finished (0/0 placed is no success)."""
    line = report.summary_line(timing)
    if not report.interrupted:
        return line
    head, sep, rest = line.partition(": ")
    return f"interrupted: {rest}" if sep and head in _STATUS_HEADS else f"interrupted: {line}"


def print_report(report: Any, timing: Any, quiet: bool, record: Path | None, extra_lines: list[str]) -> None:
    out, err = console(), console(stderr=True)
    if quiet:
        for w in report.view(timing).warnings:
            err.print(_warning(w), markup=False)
        out.print(summary_line(report, timing), markup=False)
        for line in report.failure_lines():
            out.print(f"  {line}", markup=False)
        return
    from rich.markup import escape
    from rich.table import Table

    view = report.view(timing)
    for w in view.warnings:
        out.print(escape(w) if _is_problem(w) else f"[yellow]warning:[/yellow] {escape(w)}")
    for n in view.notes:
        out.print(f"note: {n}", markup=False)
    rows = list(view.rows)
    if record is not None and not any(k == "record" for k, _ in rows):
        rows.append(("record", str(record)))
    out.print(key_value_table(view.title, rows))
    for t in view.tables:
        table = Table(title=t.title)
        for col in t.columns:
            table.add_column(col)
        for row in t.rows:
            table.add_row(*row)
        out.print(table)
    for line in view.failures:
        out.print(f"[red]failed[/red] {escape(line)}")
    for line in [*view.footer, *extra_lines]:
        out.print(line, markup=False)
    if report.interrupted:  # the finished episodes' status is not the run's
        out.print("[yellow]interrupted[/yellow]")
    elif view.status == "ok":
        out.print("[green]ok[/green]")
    elif view.status == "warn":
        out.print(f"[yellow]{escape(view.status_text)}[/yellow]")
    elif view.status_text:
        out.print(f"[red]failed[/red]: {escape(view.status_text)}")
