"""Load-fair comparisons of two or more ways to run a task, for ``bench_obstacle_modes``.

On a shared machine the CPU time of the same work swings with what the other cores do (on the
2-core laptop, a bare PyBullet loop costs 43–77 µs a step within one minute; the whole planned and
trajectory runs of issue 18 swung by 1.3–1.5× between rounds, *both* modes alike). Two whole runs
timed one after the other then compare two machine states, not two modes. Here:

* :func:`interleaved_round` opens one session per mode (world build and set-up timed and charged),
  then runs episode 0 of each mode, episode 1 of each mode, … (the order alternating), and closes
  them (timed): each mode's total is what a user's run of it costs, and a load change hits every
  mode within one episode of each other.
* :class:`Reference` is a fixed piece of physics (a world at rest stepped ``steps`` times), timed
  right before each whole run: a run that was slow because the machine was slow shows a slow
  reference next to it.
* :class:`GcTimer` sums the garbage collector's CPU time and collections (``gc.callbacks``).

CPU is ``time.process_time`` (s), wall ``time.perf_counter`` (s).
"""

from __future__ import annotations

import gc
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Cost:
    """CPU and wall seconds of one mode in one round, and its episode records."""

    cpu: float = 0.0
    wall: float = 0.0
    records: list[Any] = field(default_factory=list)

    def timed(self, f: Callable[[], Any]) -> Any:
        c0, w0 = time.process_time(), time.perf_counter()
        try:
            return f()
        finally:
            self.cpu += time.process_time() - c0
            self.wall += time.perf_counter() - w0


def interleaved_round(runners: dict[str, Callable[[], Any]], order: list[str], episodes: int) -> dict[str, Cost]:
    """One round: ``runners[m]()`` gives mode m's runner (``open_session()``); sessions opened in
    ``order``, episodes 0 .. ``episodes`` − 1 alternated between the modes (``order`` on even
    episodes, reversed on odd ones), sessions closed with their report built (as ``runner.run()``
    does). Returns each mode's :class:`Cost` (build + episodes + report + close)."""
    costs = {m: Cost() for m in order}
    sessions = {}
    for m in order:
        runner = runners[m]()
        sessions[m] = costs[m].timed(runner.open_session)
    for k in range(episodes):
        for m in order if k % 2 == 0 else order[::-1]:
            costs[m].records.append(costs[m].timed(lambda m=m, k=k: sessions[m].run(k)))
    for m in order:
        s = sessions[m]

        def finish(s: Any = s, m: str = m) -> None:
            s.report(costs[m].records, False)
            s.close()

        costs[m].timed(finish)
    return costs


class Reference:
    """CPU µs a physics step of ``world`` at rest (its bare stepping loop): the machine's speed now."""

    def __init__(self, world: Any, steps: int = 240):
        self.world, self.steps = world, steps

    def __call__(self) -> float:
        c0 = time.process_time()
        self.world.step(self.steps)
        return (time.process_time() - c0) / self.steps * 1e6


class GcTimer:
    """CPU seconds spent in the garbage collector and collections per generation while enabled."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.collections = [0, 0, 0]
        self._t0 = 0.0

    def _callback(self, phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            self._t0 = time.process_time()
        else:
            self.seconds += time.process_time() - self._t0
            self.collections[info["generation"]] += 1

    def __enter__(self) -> GcTimer:
        gc.callbacks.append(self._callback)
        return self

    def __exit__(self, *exc: object) -> None:
        gc.callbacks.remove(self._callback)
