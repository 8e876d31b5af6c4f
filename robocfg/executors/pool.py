"""``--workers N``: episodes spread over N local processes, each building its world once.

The driver hands out one batch at a time to each worker over a pipe and waits on the pipes and
on the processes' sentinels together (``multiprocessing.connection.wait``), so a worker that dies
— killed, segfaulted, out of memory — is seen at once: its unfinished batch is reported lost
with the way it died, its remaining work goes to the others, and the run never hangs. Workers
come from a fork server that has imported the recipe's modules once (no threads in it, so
forking is safe even when the driver runs Ray or a progress-bar thread), and ignore SIGINT: the
driver decides, on the first Ctrl-C, to hand out nothing more and collect what is running.
Each worker first sets up its own process (:mod:`robocfg.executors.worker_setup`: one math-library
thread, as a worker is one core's worth of work; optionally pinned to a core).
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import signal
import time
import traceback
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any

from robocfg import collector
from robocfg.errors import RobocfgError
from robocfg.executors.outcome import Execution, LostEpisodes
from robocfg.executors.session import (
    Batch,
    BatchDone,
    EpisodeRun,
    Recipe,
    ReportRequest,
    WorkerStart,
    report_in_driver,
    run_batch,
    worker_start,
)
from robocfg.executors.worker_setup import WorkerSetup, apply

POLL = 0.5  # s: how often the driver looks at the stop request while waiting
JOIN_TIMEOUT = 10.0  # s the finished workers get, together, to exit before they are terminated


class WorkerError(RobocfgError):
    """A worker raised (not a failed episode: those are records) — e.g. the world cannot be built."""


def _worker_main(conn: Connection, recipe: Recipe, setup: WorkerSetup, index: int) -> None:
    """Worker ``index``: set up its process, open the recipe once, then run the batches it is sent
    (and make the report when asked) until it is sent None."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    collector.pause()  # until its world is built (robocfg.collector)
    opening = time.time()
    try:
        set_up = apply(setup, index)
        session = recipe.open()
        conn.send(("ready", worker_start(opening, set_up)))  # the world is built: what ProcessPool.start waits for
        try:
            while (msg := conn.recv()) is not None:
                if isinstance(msg, ReportRequest):
                    conn.send(("report", session.report(msg.records, msg.interrupted)))
                    continue
                done = run_batch(session, recipe.dataset, msg, lambda run: conn.send(("episode", run)))
                conn.send(("done", done))
        finally:
            session.close()
    except BaseException as exc:  # reported to the driver, which raises it there
        conn.send(("error", f"{type(exc).__name__}: {exc}", traceback.format_exc()))
    finally:
        conn.close()


@dataclass
class _Worker:
    process: Any
    conn: Connection
    batch: Batch | None = None
    finished: int = 0  # episodes of the current batch reported so far
    ready: bool = False  # its session is open


class ProcessPool:
    """Run a recipe's episodes on ``workers`` local processes (see the module docstring)."""

    def __init__(self, workers: int, setup: WorkerSetup | None = None):
        if workers < 1:
            raise RobocfgError(f"--workers {workers}: need at least 1")
        self.workers = workers
        self.setup = setup if setup is not None else WorkerSetup()  # how each worker sets up its process
        self.pids: list[int] = []  # the worker processes' ids, once started
        self.starts: list[WorkerStart] = []  # how each worker started, filled by start()
        self._started: tuple[Recipe, list[_Worker]] | None = None

    def start(self, recipe: Recipe) -> None:
        """Start the workers for ``recipe`` and wait until each has built its world (or died):
        the fixed start of a run, which the next :meth:`run` of the same recipe then skips (a
        benchmark times it apart from the episodes). Optional: ``run`` starts them itself."""
        pool = self._spawn(recipe, self.workers)
        self._started = (recipe, pool)
        self.starts = []
        try:
            for w in pool:
                while not w.ready:
                    ready = wait([w.conn, w.process.sentinel])
                    if w.conn not in ready or not w.conn.poll():
                        break  # died while opening: run() reports what it had to do as lost
                    msg = w.conn.recv()
                    if msg[0] == "error":
                        raise WorkerError(f"worker {w.process.pid} failed: {msg[1]}\n{msg[2]}")
                    w.ready = msg[0] == "ready"
                    if w.ready:
                        self.starts.append(msg[1])
        except BaseException:
            self._started = None
            self._stop_all(pool)
            raise

    def _spawn(self, recipe: Recipe, count: int) -> list[_Worker]:
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(["robocfg.executors.boot", "robocfg.executors.pool", *recipe.preload])
        pool: list[_Worker] = []
        for i in range(count):
            parent, child = ctx.Pipe()
            proc = ctx.Process(target=_worker_main, args=(child, recipe, self.setup, i), daemon=True)
            proc.start()
            child.close()
            pool.append(_Worker(proc, parent))
        self.pids = [w.process.pid for w in pool]
        return pool

    def run(self, recipe: Recipe, batches: list[Batch], on_episode: Callable[[EpisodeRun], None] | None = None,
            should_stop: Callable[[], bool] | None = None) -> Execution:
        """Run ``batches`` on the workers :meth:`start` started for this recipe, else on new ones;
        the workers stop when it returns."""
        todo = deque(batches)
        started, self._started = self._started, None
        pool: list[_Worker] = []
        if started is not None and started[0] is not recipe:
            self._stop_all(started[1])
            started = None
        result = Execution(workers=len(started[1]) if started is not None else min(self.workers, len(batches)) or 1)
        try:
            pool = started[1] if started is not None else self._spawn(recipe, result.workers)
            for w in pool:
                self._hand_out(w, todo)
            while any(w.batch is not None for w in pool):
                if should_stop is not None and should_stop() and todo:
                    result.interrupted = True
                    todo.clear()
                busy = [w for w in pool if w.batch is not None]
                ready = wait([w.conn for w in busy] + [w.process.sentinel for w in busy], timeout=POLL)
                for w in busy:
                    if w.conn in ready or w.process.sentinel in ready:
                        self._serve(w, todo, result, on_episode)
            for lost in todo:  # only when every worker died
                result.lost.append(LostEpisodes(lost.indices, "no worker left to run it"))
            result.report = self._report(pool, recipe, result)
        finally:
            self._stop_all(pool)
        return result

    @staticmethod
    def _report(pool: list[_Worker], recipe: Recipe, result: Execution) -> Any:
        """The run's report, made by the first worker still alive (its session has the world the
        report may need); with none left, by a session opened here."""
        request = ReportRequest(result.records, result.interrupted)
        for w in pool:
            if not w.process.is_alive():
                continue
            try:
                w.conn.send(request)
                ready = wait([w.conn, w.process.sentinel])
                if w.conn in ready and w.conn.poll():
                    msg = w.conn.recv()
                    while msg[0] == "ready":  # an idle worker's first message, never read before
                        msg = w.conn.recv()
                    if msg[0] == "report":
                        return msg[1]
                    if msg[0] == "error":
                        raise WorkerError(f"worker {w.process.pid} failed: {msg[1]}\n{msg[2]}")
            except (EOFError, OSError):
                continue
        return report_in_driver(recipe, request.records, request.interrupted)

    def _hand_out(self, w: _Worker, todo: deque[Batch]) -> None:
        w.batch, w.finished = (todo.popleft() if todo else None), 0
        if w.batch is None:  # idle until the report is asked for or the pool stops
            return
        if w.process.is_alive():
            with contextlib.suppress(OSError):  # died meanwhile: its sentinel tells the rest
                w.conn.send(w.batch)

    def _serve(self, w: _Worker, todo: deque[Batch], result: Execution,
               on_episode: Callable[[EpisodeRun], None] | None) -> None:
        """Read what worker ``w`` sent; if it is gone, account for its batch."""
        while w.batch is not None:
            try:
                if not w.conn.poll():
                    break
                msg = w.conn.recv()
            except (EOFError, OSError):
                break
            if msg[0] == "ready":
                w.ready = True
            elif msg[0] == "episode":
                w.finished += 1
                if on_episode is not None:
                    on_episode(msg[1])
            elif msg[0] == "done":
                done: BatchDone = msg[1]
                result.done.append(done)
                self._hand_out(w, todo)
            else:
                raise WorkerError(f"worker {w.process.pid} failed: {msg[1]}\n{msg[2]}")
        if w.batch is not None and not w.process.is_alive():
            w.process.join()
            result.lost.append(LostEpisodes(w.batch.indices, _death(w.process.pid, w.process.exitcode)))
            w.batch = None

    @staticmethod
    def _stop_all(pool: list[_Worker]) -> None:
        """Stop every worker: all are told to stop first, then each is waited for, so their exits
        (closing the world, leaving the process) overlap instead of adding up one after another."""
        for w in pool:
            if w.process.is_alive():
                with contextlib.suppress(OSError):
                    w.conn.send(None)
        deadline = time.monotonic() + JOIN_TIMEOUT
        for w in pool:
            w.process.join(max(0.0, deadline - time.monotonic()))
            if w.process.is_alive():
                w.process.terminate()
                w.process.join()
            w.conn.close()


def _death(pid: int, code: int | None) -> str:
    if code is not None and code < 0:
        try:
            name = signal.Signals(-code).name
        except ValueError:
            name = f"signal {-code}"
        return f"worker {pid} killed by {name}"
    return f"worker {pid} exited with status {code}"
