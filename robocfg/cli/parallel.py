"""A ``run`` command's episodes on several workers (``--workers N`` or ``--executor ray``)."""

from __future__ import annotations

import dataclasses
import shutil
import time
from pathlib import Path
from typing import Any


def run_distributed(checked: Any, options: Any, workers: int, executor: str, ray_address: str | None):
    """Run ``checked`` with ``options`` (a ``RunOptions`` with the CLI's progress callback, stop
    request and dataset sink) on ``workers`` processes or Ray actors.

    Returns (``RunOutput``, the options with the sink replaced by the merged shards (closing it
    merges them into the dataset), the lost episodes)."""
    from robocfg.datasets.shards import MergedShards
    from robocfg.engine import BatchTiming, RunOutput
    from robocfg.executors.recipe import EngineRecipe
    from robocfg.executors.session import DatasetTarget, plan_batches

    sink = options.sink
    target = None
    if sink is not None:
        target = DatasetTarget(Path(sink.root).resolve(), sink.fmt, sink.fps, sink.keep, sink.language,
                               dict(sink.extra_info), sink.renderer, sink.actions, sink.limits)
    recipe = EngineRecipe.of(checked, options, target)
    pool = _executor(executor, workers, ray_address)
    t0 = time.perf_counter()
    try:
        execution = pool.run(recipe, _missing(plan_batches(options.episodes, pool.workers, target is not None),
                                              options.resumed), options.on_episode, options.should_stop)
    except BaseException:
        if target is not None:
            shutil.rmtree(target.root / ".shards", ignore_errors=True)
        raise
    runs = execution.runs
    timing = BatchTiming(time.perf_counter() - t0, [r.wall for r in runs], [r.physics for r in runs])
    if target is not None:
        options = dataclasses.replace(options, sink=MergedShards(execution.shards, target.root, target.fmt,
                                                                 target.extra_info, target.limits))
    report = execution.report
    if options.resumed:  # the report of every finished episode, those of the interrupted run included
        from robocfg.executors.session import report_in_driver

        records = sorted([*options.resumed, *(r.record for r in runs)], key=lambda r: int(r.index))
        report = report_in_driver(recipe, records, execution.interrupted)
    return RunOutput(report, timing), options, execution.lost


def _missing(batches: list[Any], resumed: tuple[Any, ...]) -> list[Any]:
    """The batches without the episodes a resumed run already has (``--resume``)."""
    from robocfg.executors.session import Batch

    done = {int(r.index) for r in resumed}
    kept = (Batch(b.id, tuple(k for k in b.indices if k not in done)) for b in batches)
    return [b for b in kept if b.indices]


def _executor(kind: str, workers: int, address: str | None):
    if kind == "ray":
        from robocfg.executors.ray_pool import RayPool

        return RayPool(workers, address)
    from robocfg.executors.pool import ProcessPool

    return ProcessPool(workers)


def lost_lines(lost: list[Any]) -> list[str]:
    """One line per loss: which episodes, and why."""
    return [f"lost episode{'s' if len(x.indices) > 1 else ''} {', '.join(map(str, x.indices))}: {x.reason} "
            f"(the report and dataset hold the others)" for x in lost]


def with_lost(report: Any, lost: list[Any]) -> Any:
    """The JSON payload: the report, plus ``lost_episodes`` when workers died (exit 1)."""
    if not lost:
        return report
    return dataclasses.asdict(report) | {"lost_episodes": [{"episodes": list(x.indices), "reason": x.reason}
                                                           for x in lost]}
