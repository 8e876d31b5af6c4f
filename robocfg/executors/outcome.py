"""What an executor hands back: the committed batches, the episodes it lost and why."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from robocfg.executors.session import BatchDone, EpisodeRun

if TYPE_CHECKING:
    from robocfg.datasets.shards import Shard


@dataclass(frozen=True)
class LostEpisodes:
    """Episodes that did not finish because the worker running them died (``reason``: how, e.g.
    ``worker 4711 killed by SIGKILL``) or because no worker was left to run them."""

    indices: tuple[int, ...]
    reason: str


@dataclass
class Execution:
    """The result of distributing a run: committed batches (any order), lost episodes, whether
    it stopped early on request (SIGINT/SIGTERM), the workers used, and the run's report (made by
    a worker's session from every finished episode, as a single process makes it)."""

    done: list[BatchDone] = field(default_factory=list)
    lost: list[LostEpisodes] = field(default_factory=list)
    interrupted: bool = False
    workers: int = 1
    report: Any = None

    @property
    def runs(self) -> list[EpisodeRun]:
        """Every finished episode, ordered by episode index (the order a single process runs them)."""
        return sorted((r for b in self.done for r in b.runs), key=lambda r: r.index)

    @property
    def records(self) -> list[Any]:
        return [r.record for r in self.runs]

    @property
    def shards(self) -> list[Shard]:
        return [b.shard for b in sorted(self.done, key=lambda b: b.batch.id) if b.shard is not None]

    @property
    def lost_indices(self) -> list[int]:
        return sorted(k for lost in self.lost for k in lost.indices)
