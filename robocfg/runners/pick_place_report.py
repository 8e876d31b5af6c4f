"""Typed results of ``run pick-place``. JSON holds no wall-clock figures, so the same seed gives
the same JSON; wall times are kept apart in ``PickPlaceTiming``."""

from __future__ import annotations

from dataclasses import dataclass, field

from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION

PHASES = ("pre_grasp", "approach", "grasp", "lift", "transport", "lower", "release", "retract")


@dataclass
class PhaseRecord:
    """One phase: simulated start/end time (s), whether it converged, and why not."""

    name: str
    t_start: float
    t_end: float
    ok: bool
    detail: str = ""


@dataclass
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
class PickPlaceReport:
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


@dataclass
class PickPlaceTiming:
    """Wall-clock figures (not part of the deterministic JSON)."""

    wall_time: float = 0.0
    per_episode: list[float] = field(default_factory=list)
    physics_per_episode: list[float] = field(default_factory=list)  # s inside p.stepSimulation

    @property
    def mean_physics(self) -> float:
        n = len(self.physics_per_episode)
        return sum(self.physics_per_episode) / n if n else 0.0

    @property
    def mean_episode(self) -> float:
        return sum(self.per_episode) / len(self.per_episode) if self.per_episode else 0.0


def summarise(episodes: list[EpisodeResult]) -> PickPlaceSummary:
    n = len(episodes)
    ok = sum(e.success for e in episodes)
    fails: dict[str, int] = {}
    for e in episodes:
        if not e.success and e.failed_phase:
            fails[e.failed_phase] = fails.get(e.failed_phase, 0) + 1
    mean_sim = sum(e.sim_time for e in episodes) / n if n else 0.0
    return PickPlaceSummary(n, ok, ok / n if n else 0.0, fails, mean_sim)
