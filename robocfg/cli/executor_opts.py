"""``--workers``, ``--executor`` and ``--ray-address``: where a run's episodes are simulated."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

import typer

WorkersOpt = Annotated[int | None, typer.Option(
    "--workers", "-j", min=1,
    help="Processes to spread the episodes over, each building its world once (default: one per CPU core, "
         "at most one per 4 episodes, so short runs stay in one process). Same seed, same report and "
         "dataset whatever the count.")]
ExecutorOpt = Annotated[str, typer.Option(
    "--executor", help="local (processes on this machine) or ray (Ray actors: RAY_ADDRESS or --ray-address, "
                       "else a local Ray).")]
RayAddressOpt = Annotated[str | None, typer.Option(
    "--ray-address", help="Ray cluster to run on with --executor ray (default: RAY_ADDRESS, else a local Ray).")]

EPISODES_PER_WORKER = 4  # below this a worker's world build is not paid back


def cpu_cores() -> int:
    """CPU cores this process may use (its affinity mask, which containers and taskset narrow)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def resolve_workers(workers: int | None, episodes: int, executor: str, gui: bool) -> int:
    """The worker count: the option, else one per core and at most one per 4 episodes."""
    if executor not in ("local", "ray"):
        raise typer.BadParameter(f"{executor!r}: choose local or ray", param_hint="--executor")
    if gui and ((workers or 1) > 1 or executor == "ray"):
        raise typer.BadParameter("--gui shows one world: run it with --workers 1 and --executor local",
                                 param_hint="--workers")
    if workers is None:
        workers = 1 if gui else max(1, min(cpu_cores(), episodes // EPISODES_PER_WORKER))
    return min(workers, episodes)


def absolute_if_file(name: str | None) -> str | None:
    """A ``--robot`` given as a file path, made absolute so that a worker with another working
    directory finds it; a robot name stays as it is."""
    if name is not None and Path(name).is_file():
        return str(Path(name).resolve())
    return name
