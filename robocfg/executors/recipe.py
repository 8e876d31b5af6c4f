"""Any episodic task kind as a recipe a worker opens into a session, through the episode engine.

The recipe carries the task as its validated document (``robocfg.engine.TaskSource``) and the run
options without their in-process callbacks, so it pickles to a few kilobytes. A worker opens it
with ``robocfg.engine.open_session`` — the same session class a single-process run loops over —
so episode k's record is, by construction, the one a batch run records for k. Dataset recording
goes through a :class:`ShardSwitch` installed as the session's sink: each batch points it at its
own shard.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from robocfg.executors.session import DatasetTarget, EpisodeRun
from robocfg.executors.usage import Usage

if TYPE_CHECKING:
    from robocfg.datasets.sink import DatasetSink
    from robocfg.engine import RunOptions, TaskSource

# What every worker needs whatever the kind: imported once by a process pool's fork server.
COMMON_PRELOAD = ("robocfg.sim.world", "robocfg.engine", "robocfg.kinematics.model")
# What a worker needs to write shards: only when the run records a dataset (it imports
# scipy.spatial, pyarrow's writers...: 0.5 s on the 2-core laptop that a run without one never uses).
DATASET_PRELOAD = ("robocfg.datasets.shards",)


@dataclass(frozen=True)
class EngineRecipe:
    """A run of ``task`` with ``options`` (portable: no callbacks, no sink), recorded into
    ``dataset`` when given; ``runner_module`` is the kind's module (preloaded by pools)."""

    task: TaskSource
    options: RunOptions
    dataset: DatasetTarget | None = None
    runner_module: str = ""

    @classmethod
    def of(cls, checked: Any, options: RunOptions, dataset: DatasetTarget | None = None) -> EngineRecipe:
        from robocfg.engine import TaskSource, runner_for

        seed = options.resolved_seed(checked.config.sim.seed)
        portable = dataclasses.replace(options.portable(), seed=seed)
        return cls(TaskSource.of(checked), portable, dataset, runner_for(checked.config.task).__module__)

    @property
    def episodes(self) -> int:
        return self.options.episodes

    @property
    def preload(self) -> tuple[str, ...]:
        dataset = DATASET_PRELOAD if self.dataset is not None else ()
        runner = (self.runner_module,) if self.runner_module else ()
        return (*COMMON_PRELOAD, *dataset, *runner)

    def open(self) -> EngineSession:
        return EngineSession(self)


class ShardSwitch:
    """The sink a worker's session records into: it passes every episode to the current batch's
    shard sink (``target``), so one session serves many shards."""

    def __init__(self) -> None:
        self.target: DatasetSink | None = None

    def begin(self, *args: Any, **kwargs: Any) -> Any:
        if self.target is None:
            raise RuntimeError("an episode is recorded with no shard to write it to")
        return self.target.begin(*args, **kwargs)

    def end(self, *args: Any, **kwargs: Any) -> None:
        if self.target is not None:
            self.target.end(*args, **kwargs)


class EngineSession:
    """A worker's engine session (world built once) behind the executors' ``Session`` protocol."""

    def __init__(self, recipe: EngineRecipe):
        from robocfg.sim.quiet import quiet_import

        quiet_import()
        from robocfg.engine import open_session

        self.task = recipe.task.load()
        self.switch = ShardSwitch() if recipe.dataset is not None else None
        self.session: Any = open_session(self.task, dataclasses.replace(recipe.options, sink=self.switch))

    def run(self, k: int, sink: DatasetSink | None = None) -> EpisodeRun:
        if self.switch is not None:
            self.switch.target = sink
        usage, cpu, thread = Usage.now(), time.process_time(), time.thread_time()
        record = self.session.run(k)
        cpu, thread = time.process_time() - cpu, time.thread_time() - thread
        usage = Usage.now() - usage
        t = self.session.timing
        return EpisodeRun(record, t.per_episode[-1], t.physics_per_episode[-1], cpu, thread, usage)

    def report(self, records: list[Any], interrupted: bool) -> Any:
        return self.session.report(records, interrupted)

    def close(self) -> None:
        self.session.close()
