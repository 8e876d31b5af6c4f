"""What every multi-episode ``run`` command shares: the progress bar, stopping cleanly on
SIGINT/SIGTERM, the ``--record-episode`` range check and the failure lines (one per distinct
phase and reason, with its count)."""

from __future__ import annotations

import signal
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass

import typer

from robocfg.engine.options import EpisodeOutcome
from robocfg.engine.runner import failure_lines

__all__ = ["StopRequest", "check_record_episode", "failure_lines", "interrupted_line", "progress_bar", "stop_on_signals"]


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


def interrupted_line(stop: StopRequest, done: int, episodes: int, json_path: object) -> str:
    where = f"; report of the finished episodes in {json_path}" if json_path is not None else ""
    return f"interrupted ({stop.signal_name}) after {done}/{episodes} episodes{where}"
