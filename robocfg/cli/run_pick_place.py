"""``run pick-place``'s front-end part: the ``--dataset*`` options (declared by the kind) become a
dataset sink that records every episode; afterwards the sink is closed and its summary printed."""

from __future__ import annotations

import dataclasses
from typing import Any

from robocfg.cli.dataset_opts import dataset_sink
from robocfg.cli.run_command import HOOKS, CliHook


def _prepare(task: Any, options: Any, robot: str | None) -> Any:
    from robocfg.datasets.language import pick_place_instruction

    x = options.extras
    if x is None or x.dataset is None:
        return options
    seed = options.resolved_seed(task.config.sim.seed)
    sink = dataset_sink(x.dataset, x.dataset_format, x.dataset_fps, x.keep, task, seed, options.arm, robot,
                        pick_place_instruction(task.config.pick_place))
    return dataclasses.replace(options, sink=sink)


def _finish(options: Any, report: Any) -> list[str]:
    if options.sink is None:
        return []
    written = options.sink.close()
    return [f"dataset ({written.format}): {written.episodes_kept}/{written.episodes_run} episodes kept, "
            f"{written.frames} frames → {written.path}"]


HOOKS["pick_place"] = CliHook(_prepare, _finish)
