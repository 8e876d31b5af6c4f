"""Typed results of ``run grasp``. The JSON report holds no wall-clock figures (same seed ⇒ same
JSON); planning and perception times are kept apart in ``GraspTiming``."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from robocfg.engine.runner import EpisodesReport, ReportView
from robocfg.engine.session import BatchTiming
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, failed_episodes_line


@dataclass(slots=True)
class AttemptRecord:
    """One grasp attempt: the candidate tried (GraspNet frame, world m), and how it ended."""

    candidate: dict
    rank: int
    success: bool
    failed_phase: str | None
    reason: str


@dataclass(slots=True)
class GraspEpisode:
    """One episode. ``object_start``: x, y, z (m) where the object was spawned, ``object_start_yaw_deg``
    the yaw added by the randomisation; ``rejected``: candidate counts per
    rejection reason in the first plan; ``lift_rise``: how far the object rose (m)."""

    index: int
    seed: int
    object: str
    object_start: list[float]
    object_start_yaw_deg: float
    success: bool
    first_attempt_success: bool
    failed_phase: str | None
    reason: str
    object_points: int
    poses_evaluated: int
    candidates: int
    rejected: dict[str, int]
    chosen_score: float | None
    lift_rise: float | None
    sim_time: float
    attempts: list[AttemptRecord] = field(default_factory=list)


@dataclass
class GraspSummary:
    episodes: int
    successes: int
    success_rate: float
    first_attempt_rate: float
    mean_attempts: float
    by_object: dict[str, str]
    failures_by_phase: dict[str, int]


@dataclass
class GraspReport(EpisodesReport):
    """The ``--json`` report. ``interrupted``: the run was stopped (SIGINT/SIGTERM) and
    ``episodes`` holds only the episodes that finished."""

    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)
    task: str
    robot: str
    arm: str
    seed: int
    summary: GraspSummary
    episodes: list[GraspEpisode]
    warnings: list[str] = field(default_factory=list)
    interrupted: bool = False

    def summary_line(self, timing: BatchTiming | None = None) -> str:
        s = self.summary
        ok = "ok" if s.successes == s.episodes else "failed"
        plan = f", planning median {timing.median_planning:.2f} s" if isinstance(timing, GraspTiming) else ""
        return f"{ok}: {self.robot} lifted {s.successes}/{s.episodes} ({s.success_rate:.1%}){plan}"

    def view(self, timing: BatchTiming | None = None) -> ReportView:
        s = self.summary
        failed = [e for e in self.episodes if not e.success]
        rows = [("episodes", str(s.episodes)),
                ("lift success", f"{s.successes}/{s.episodes} ({s.success_rate:.1%}); first attempt {s.first_attempt_rate:.1%}"),
                ("by object", ", ".join(f"{k} {v}" for k, v in s.by_object.items())),
                ("failures by phase", ", ".join(f"{k}: {v}" for k, v in s.failures_by_phase.items()) or "none")]
        if isinstance(timing, GraspTiming):
            rows += [("planning time (median)", f"{timing.median_planning:.3f} s over {len(timing.planning)} plans"),
                     ("perception time (median)", f"{timing.median_perception:.3f} s (render + cloud)"),
                     ("wall time / episode", f"{timing.mean_episode:.2f} s")]
        if s.episodes == 1:
            e = self.episodes[0]
            rows += [("object points", str(e.object_points)), ("poses evaluated", str(e.poses_evaluated)),
                     ("reachable candidates", str(e.candidates)),
                     ("rejected", ", ".join(f"{k} {v}" for k, v in e.rejected.items() if v) or "none"),
                     ("chosen score", "-" if e.chosen_score is None else f"{e.chosen_score:.3f}"),
                     ("attempts", str(len(e.attempts)))]
        footer = []
        if failed:
            footer.append(failed_episodes_line([f"{e.index} ({e.object})" for e in failed]))
        return ReportView(f"run grasp: {self.robot} (arm {self.arm}), seed {self.seed}", rows,
                          warnings=list(self.warnings), failures=self.failure_lines(), footer=footer,
                          status="failed" if failed else "ok")


@dataclass
class GraspTiming(BatchTiming):
    """Wall times (s): ``planning`` per plan (sampling → ranked reachable grasps), ``perception``
    per capture (rendering + cloud), besides the batch's ``per_episode`` and ``wall_time``."""

    planning: list[float] = field(default_factory=list)
    perception: list[float] = field(default_factory=list)

    @property
    def median_planning(self) -> float:
        return float(np.median(self.planning)) if self.planning else 0.0

    @property
    def median_perception(self) -> float:
        return float(np.median(self.perception)) if self.perception else 0.0


def summarise(episodes: list[GraspEpisode]) -> GraspSummary:
    n = len(episodes)
    ok = sum(e.success for e in episodes)
    by: dict[str, list[int]] = {}
    fails: dict[str, int] = {}
    for e in episodes:
        by.setdefault(e.object, [0, 0])
        by[e.object][0] += e.success
        by[e.object][1] += 1
        if not e.success:
            fails[e.failed_phase or "?"] = fails.get(e.failed_phase or "?", 0) + 1
    return GraspSummary(
        episodes=n, successes=ok, success_rate=round(ok / n, 6) if n else 0.0,
        first_attempt_rate=round(sum(e.first_attempt_success for e in episodes) / n, 6) if n else 0.0,
        mean_attempts=round(sum(len(e.attempts) for e in episodes) / n, 4) if n else 0.0,
        by_object={k: f"{v[0]}/{v[1]}" for k, v in by.items()}, failures_by_phase=fails)
