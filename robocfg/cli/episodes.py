"""What every multi-episode ``run`` command shares: the progress bar, stopping cleanly on
SIGINT/SIGTERM, the ``--record-episode`` range check and the failure lines (one per distinct
phase and reason, with its count)."""

from __future__ import annotations

import signal
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Protocol

import typer


class EpisodeOutcome(Protocol):
    """The fields of an episode record that the shared printing reads."""

    success: bool
    failed_phase: str | None
    reason: str


@dataclass
class StopRequest:
    """Set by the first SIGINT/SIGTERM: the runner finishes the episode it is in, then stops.
    A second signal interrupts at once (KeyboardInterrupt, exit 130, no report)."""

    signal_name: str | None = None

    def __call__(self) -> bool:
        return self.signal_name is not None


@contextmanager
def stop_on_signals() -> Iterator[StopRequest]:
    """Install the SIGINT/SIGTERM handlers for the duration of a run; the old ones come back after."""
    stop = StopRequest()

    def handler(signum: int, _frame: object) -> None:
        if stop.signal_name is not None:
            raise KeyboardInterrupt
        stop.signal_name = signal.Signals(signum).name

    old = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield stop
    finally:
        for s, h in old.items():
            signal.signal(s, h)


def check_record_episode(record_episode: int, episodes: int, recording: bool) -> None:
    """``--record-episode`` must name an episode that runs (checked before simulating: exit 2)."""
    if recording and record_episode >= episodes:
        raise typer.BadParameter(f"episode {record_episode} does not run: episodes are 0..{episodes - 1}",
                                 param_hint="--record-episode")


@contextmanager
def progress_bar(label: str, episodes: int, verb: str, show: bool) -> Iterator[Callable[[EpisodeOutcome], None] | None]:
    """A transient progress bar on stderr counting successes (``"3 placed"``); yields the
    per-episode callback, or None when no bar is shown (one episode, or ``-q``)."""
    if not show:
        yield None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeRemainingColumn,
    )

    from robocfg.cli.common import console

    with Progress(TextColumn(label), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[ok]}"),
                  TimeRemainingColumn(), console=console(stderr=True), transient=True) as bar:
        tid = bar.add_task("episodes", total=episodes, ok="")
        done = [0]

        def tick(res: EpisodeOutcome) -> None:
            done[0] += res.success
            bar.update(tid, advance=1, ok=f"{done[0]} {verb}")

        yield tick


def failure_lines(episodes: Sequence[EpisodeOutcome]) -> list[str]:
    """One line per distinct (phase, reason) among the failed episodes, most frequent first."""
    counts = Counter((e.failed_phase or "?", e.reason) for e in episodes if not e.success)
    return [f"{n} × {phase}: {reason}" for (phase, reason), n in counts.most_common()]


def interrupted_line(stop: StopRequest, done: int, episodes: int, json_path: object) -> str:
    where = f"; report of the finished episodes in {json_path}" if json_path is not None else ""
    return f"interrupted ({stop.signal_name}) after {done}/{episodes} episodes{where}"
