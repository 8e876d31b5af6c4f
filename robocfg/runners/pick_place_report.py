"""Typed results of ``run pick-place``. JSON holds no wall-clock figures, so the same seed gives
the same JSON; wall times are kept apart in ``PickPlaceTiming``."""

from __future__ import annotations

from dataclasses import dataclass, field

from robocfg.engine.runner import EpisodesReport, ReportView
from robocfg.engine.session import BatchTiming
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, failed_episodes_line

PHASES = ("pre_grasp", "approach", "grasp", "lift", "transport", "lower", "release", "retract")


@dataclass(slots=True)
class PhaseRecord:
    """One phase: simulated start/end time (s), whether it converged, and why not."""

    name: str
    t_start: float
    t_end: float
    ok: bool
    detail: str = ""


@dataclass(slots=True)
class EpisodeResult:
    """One episode. Positions in m (world), angles in deg."""

    index: int
    seed: int
    success: bool
    failed_phase: str | None
    reason: str
    object_start: list[float]  # x, y, z (m): where the randomised object was spawned
    object_start_yaw_deg: float  # its yaw about world z
    place_target: list[float]  # x, y (m)
    object_final: list[float]  # x, y, z (m)
    place_error: float | None  # horizontal distance (m)
    tilt_deg: float | None
    lift_rise: float | None  # how far the object rose during lift (m)
    mass: float
    friction: float
    sim_time: float  # s
    steps: int
    phases: list[PhaseRecord] = field(default_factory=list)


@dataclass
class PickPlaceSummary:
    episodes: int
    successes: int
    success_rate: float
    failures_by_phase: dict[str, int]
    mean_sim_time: float


@dataclass
class PickPlaceReport(EpisodesReport):
    """The ``--json`` report. ``interrupted``: the run was stopped (SIGINT/SIGTERM) and
    ``episodes`` holds only the episodes that finished."""

    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)
    task: str
    robot: str
    arm: str
    seed: int
    summary: PickPlaceSummary
    episodes: list[EpisodeResult]
    warnings: list[str] = field(default_factory=list)
    interrupted: bool = False

    def summary_line(self, timing: BatchTiming | None = None) -> str:
        s = self.summary
        ok = "ok" if s.successes == s.episodes else "failed"
        return (f"{ok}: {self.robot} placed {s.successes}/{s.episodes} ({s.success_rate:.1%}), "
                f"{s.mean_sim_time:.2f} s simulated per episode")

    def view(self, timing: BatchTiming | None = None) -> ReportView:
        s = self.summary
        failed = [e for e in self.episodes if not e.success]
        rows = [("episodes", str(s.episodes)), ("success", f"{s.successes}/{s.episodes} ({s.success_rate:.1%})"),
                ("failures by phase", ", ".join(f"{k}: {v}" for k, v in s.failures_by_phase.items()) or "none"),
                ("simulated time / episode", f"{s.mean_sim_time:.2f} s")]
        if timing is not None:
            rows.append(("wall time / episode", f"{timing.mean_episode:.3f} s (total {timing.wall_time:.1f} s)"))
        if s.episodes == 1:
            e = self.episodes[0]
            rows += [("place error", f"{(e.place_error or 0.0) * 100:.2f} cm"), ("tilt", f"{e.tilt_deg or 0.0:.1f}°")]
        footer = []
        if failed:
            footer.append(failed_episodes_line([str(e.index) for e in failed]))
        return ReportView(f"run pick-place: {self.robot} (arm {self.arm}), seed {self.seed}", rows,
                          warnings=list(self.warnings), failures=self.failure_lines(), footer=footer,
                          status="failed" if failed else "ok")


PickPlaceTiming = BatchTiming  # wall-clock figures, kept apart from the deterministic JSON


def summarise(episodes: list[EpisodeResult]) -> PickPlaceSummary:
    n = len(episodes)
    ok = sum(e.success for e in episodes)
    fails: dict[str, int] = {}
    for e in episodes:
        if not e.success and e.failed_phase:
            fails[e.failed_phase] = fails.get(e.failed_phase, 0) + 1
    mean_sim = sum(e.sim_time for e in episodes) / n if n else 0.0
    return PickPlaceSummary(n, ok, ok / n if n else 0.0, fails, mean_sim)
