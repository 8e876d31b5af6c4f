"""Typed results of ``run pick-place-many``: one record per object inside one record per episode.
No wall-clock figures, so the same seed gives the same JSON."""

from __future__ import annotations

from dataclasses import dataclass, field

from robocfg.engine.runner import EpisodesReport, ReportView
from robocfg.engine.session import BatchTiming
from robocfg.runners.pick_place_report import PhaseRecord
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, failed_episodes_line


@dataclass
class ObjectRecord:
    """One object's pick and place. Positions in m (world), angles in deg. ``attempted``: False
    when the episode ended on an earlier object's failure; ``grasp_candidates``: candidates from
    the geometry; ``grasps_in_collision``: of those, dropped because the arm or gripper would touch
    a neighbour or a fixture at the grasp or pre-grasp configuration."""

    name: str
    attempted: bool
    success: bool
    failed_phase: str | None
    reason: str
    start: list[float]
    start_yaw_deg: float
    place_target: list[float]  # x, y (m)
    final: list[float]
    place_error: float | None  # horizontal distance (m)
    tilt_deg: float | None
    grasp_candidates: int = 0
    grasps_in_collision: int = 0
    phases: list[PhaseRecord] = field(default_factory=list)


@dataclass
class ManyEpisode:
    """One episode: ``success`` when every object was placed. A failure names the object
    (``failed_object``) and the phase; ``reason`` starts with the object's name.
    ``robot_fixture_contacts``: polls (every 4 physics steps) at which the robot touched a fixture
    part or an obstacle; ``first_contact`` names the first (phase, link, part);
    ``contacts_by_kind`` counts the polls per ``"phase: link touched part"``. A contact is a point
    PyBullet reports at distance ≤ 0; ``closest_fixture`` is the smallest robot–fixture distance
    PyBullet reported at a poll (m; it reports pairs up to a few mm apart; None: none that close)."""

    index: int
    seed: int
    success: bool
    failed_phase: str | None
    failed_object: str | None
    reason: str
    placed: int
    order: list[str]
    robot_fixture_contacts: int
    first_contact: str | None
    sim_time: float  # s
    steps: int
    objects: list[ObjectRecord] = field(default_factory=list)
    contacts_by_kind: dict[str, int] = field(default_factory=dict)
    closest_fixture: float | None = None


@dataclass
class ManySummary:
    episodes: int
    successes: int
    success_rate: float
    objects_placed: int
    objects_total: int
    failures_by_phase: dict[str, int]
    failures_by_object: dict[str, int]
    robot_fixture_contacts: int
    episodes_with_contact: int
    mean_sim_time: float
    contacts_by_kind: dict[str, int] = field(default_factory=dict)  # polls per "phase: link touched part"
    closest_fixture: float | None = None  # m: the smallest robot–fixture distance PyBullet reported


def summarise(episodes: list[ManyEpisode]) -> ManySummary:
    n = len(episodes)
    ok = sum(e.success for e in episodes)
    by_phase: dict[str, int] = {}
    by_object: dict[str, int] = {}
    by_kind: dict[str, int] = {}
    for e in episodes:
        for kind, c in e.contacts_by_kind.items():
            by_kind[kind] = by_kind.get(kind, 0) + c
        if not e.success:
            by_phase[e.failed_phase or "?"] = by_phase.get(e.failed_phase or "?", 0) + 1
            by_object[e.failed_object or "?"] = by_object.get(e.failed_object or "?", 0) + 1
    return ManySummary(n, ok, ok / n if n else 0.0, sum(e.placed for e in episodes),
                       sum(len(e.objects) for e in episodes), by_phase, by_object,
                       sum(e.robot_fixture_contacts for e in episodes),
                       sum(e.robot_fixture_contacts > 0 for e in episodes),
                       sum(e.sim_time for e in episodes) / n if n else 0.0, dict(sorted(by_kind.items())),
                       min((e.closest_fixture for e in episodes if e.closest_fixture is not None), default=None))


@dataclass
class ManyReport(EpisodesReport):
    """The ``--json`` report of ``run pick-place-many``."""

    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)
    task: str
    robot: str
    arm: str
    seed: int
    summary: ManySummary
    episodes: list[ManyEpisode]
    warnings: list[str] = field(default_factory=list)
    interrupted: bool = False

    def summary_line(self, timing: BatchTiming | None = None) -> str:
        s = self.summary
        ok = "ok" if s.successes == s.episodes else "failed"
        return (f"{ok}: {self.robot} cleared {s.successes}/{s.episodes} episodes ({s.success_rate:.1%}), "
                f"{s.objects_placed}/{s.objects_total} objects placed, {s.robot_fixture_contacts} robot-fixture contacts")

    def view(self, timing: BatchTiming | None = None) -> ReportView:
        s = self.summary
        failed = [e for e in self.episodes if not e.success]
        rows = [("episodes", str(s.episodes)), ("success", f"{s.successes}/{s.episodes} ({s.success_rate:.1%})"),
                ("objects placed", f"{s.objects_placed}/{s.objects_total}"),
                ("failures by phase", ", ".join(f"{k}: {v}" for k, v in s.failures_by_phase.items()) or "none"),
                ("failures by object", ", ".join(f"{k}: {v}" for k, v in s.failures_by_object.items()) or "none"),
                ("robot-fixture contacts", f"{s.robot_fixture_contacts} (in {s.episodes_with_contact} episodes)"),
                ("simulated time / episode", f"{s.mean_sim_time:.2f} s")]
        if s.closest_fixture is not None:
            rows.insert(6, ("closest robot-fixture distance", f"{s.closest_fixture * 1000:.1f} mm"))
        if s.contacts_by_kind:
            rows.insert(6, ("contacts by phase and link", ", ".join(f"{k} ×{v}" for k, v in s.contacts_by_kind.items())))
        if timing is not None:
            rows.append(("wall time / episode", f"{timing.mean_episode:.3f} s (total {timing.wall_time:.1f} s)"))
        footer = [failed_episodes_line([str(e.index) for e in failed])] if failed else []
        return ReportView(f"run pick-place-many: {self.robot} (arm {self.arm}), seed {self.seed}", rows,
                          warnings=list(self.warnings), failures=self.failure_lines(), footer=footer,
                          status="failed" if failed else "ok")
