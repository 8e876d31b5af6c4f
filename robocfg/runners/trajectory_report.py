"""``run trajectory``'s report: the planned, checked and followed trajectory as plain data
(JSON-ready; times in s, joint values in rad), its table view, and the q, q̇, q̈ plot.

Kept apart from :mod:`robocfg.runners.trajectory` (planning and following) as the other kinds keep
their reports (``pick_place_report``, ``grasp_report``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from robocfg.engine.runner import ReportView, TableView
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, SingleRunReport


@dataclass
class Samples:
    """The planned trajectory sampled at ``rate`` Hz: t (s), q (rad), qd (rad/s), qdd (rad/s²)."""

    rate: float
    t: list[float]
    q: list[list[float]]
    qd: list[list[float]]
    qdd: list[list[float]]


@dataclass
class TrajectoryResult(SingleRunReport):
    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)  # of the --json report
    task: str
    robot: str
    arm: str
    joint_names: list[str]
    method: str  # toppra | trapezoid | ruckig | hold
    path: str  # spline | pchip | linear | none
    stop_at_waypoints: bool
    duration: float  # s
    planning_time_ms: float
    gridpoints: int | None
    fit_factor: float
    waypoints: list[list[float]]  # distinct waypoints used (rad)
    waypoint_indices: list[int]  # their indices in the task's list
    waypoint_kinds: list[str]
    waypoint_times: list[float]  # s
    limits: dict  # lower, upper, velocity, acceleration, jerk (per joint)
    limit_check: dict  # violations at 1 kHz and peak ratios
    tracking: dict | None = None  # rms/max/final/settled per joint and overall (rad)
    samples: Samples | None = None
    measured: dict | None = None  # simulated t (s) and q (rad) at every physics step
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    success: bool = False
    sim_time: float = 0.0
    wall_time: float = 0.0
    record: str | None = None
    plot: str | None = None
    interrupted: bool = False  # stopped by SIGINT/SIGTERM while following


    def summary_line(self, timing: object = None) -> str:
        tr = self.tracking
        track = "" if tr is None else f", tracking RMS {tr['rms']:.2e} rad, final {tr['final']:.2e} rad"
        status = "ok" if self.success else "FAILED"
        return (f"{status}: {self.robot} {len(self.waypoints)} waypoints, {self.method}, duration {self.duration:.3f} s, "
                f"planned in {self.planning_time_ms:.1f} ms, {self.limit_check['total']} limit violations at 1 kHz{track}")

    def view(self, timing: object = None) -> ReportView:
        lc = self.limit_check
        rows = [
            ("method", f"{self.method} ({self.path} path" + (f", {self.gridpoints} gridpoints" if self.gridpoints else "") + ")"),
            ("stop at waypoints", str(self.stop_at_waypoints)),
            ("duration", f"{self.duration:.3f} s"),
            ("planning time", f"{self.planning_time_ms:.1f} ms"),
            ("limit violations (1 kHz)", f"{lc['total']} (peak |q̇|/limit {lc['peak_velocity_ratio']:.4f}, "
                                         f"|q̈|/limit {lc['peak_acceleration_ratio']:.4f})"),
        ]
        t = self.tracking
        if t is not None:
            rows += [("tracking RMS / max", f"{t['rms']:.2e} / {t['max']:.2e} rad (worst joint)"),
                     ("final error", f"{t['final']:.2e} rad at the end, {t['settled']:.2e} rad after {t['settle_time']:.2f} s"),
                     ("simulated / wall time", f"{self.sim_time:.2f} s / {self.wall_time:.2f} s")]
        rows += [(k, v) for k, v in (("plot", self.plot), ("record", self.record)) if v]
        tables = [TableView("waypoints", ["#", "from", "t (s)", *self.joint_names],
                            [[str(i), self.waypoint_kinds[k], f"{tw:.3f}", *(f"{v:+.3f}" for v in q)]
                             for k, (i, q, tw) in enumerate(zip(self.waypoint_indices, self.waypoints,
                                                                self.waypoint_times, strict=True))])]
        if t is not None:
            lim = self.limits
            tables.append(TableView("tracking error per joint (rad)", ["joint", "v max", "a max", "RMS", "max", "final"],
                                    [[n, f"{lim['velocity'][k]:.3f}", f"{lim['acceleration'][k]:.2f}",
                                      f"{t['rms_per_joint'][k]:.2e}", f"{t['max_per_joint'][k]:.2e}",
                                      f"{t['final_per_joint'][k]:.2e}"] for k, n in enumerate(self.joint_names)]))
        return ReportView(f"run trajectory: {self.robot} ({self.arm})", rows, tables=tables, warnings=list(self.warnings),
                          notes=list(self.notes), status="ok" if self.success else "failed",
                          status_text="" if self.success else "limit violations")


def plot_result(r: TrajectoryResult, path: Path) -> None:
    """q, q̇, q̈ per joint against time into ``path`` (PNG); the measured q too when followed."""
    from robocfg.motion.plot import plot_trajectory

    s = r.samples
    assert s is not None
    measured = (r.measured["t"], r.measured["q"]) if r.measured else None
    title = (f"{r.robot}: {r.method} ({r.path} path), duration {r.duration:.3f} s — "
             "limits dashed, waypoints dotted")
    r.plot = str(plot_trajectory(path, s.t, s.q, s.qd, s.qdd, r.joint_names, r.limits, r.waypoint_times,
                                 measured, title))
