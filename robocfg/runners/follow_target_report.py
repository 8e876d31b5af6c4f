"""Typed result of ``run follow-target`` and the statistics made from the measured series.

Units are in the field names (``_mm``, ``_deg``, ``_ms``) or next to the field; the series are
(t s, position error m, orientation error rad, clearance m) per control step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from robocfg.config.commands import FollowTargetParams
from robocfg.engine.runner import ReportView
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, SingleRunReport

SAMPLE_RATE = 60.0  # Hz of the samples kept in the result
FINAL_WINDOW = 0.25  # s averaged for the final (residual) error


@dataclass
class Stats:
    """mean / RMS / max of a series (units in the field name of the owner)."""

    mean: float
    rms: float
    max: float

    @classmethod
    def of(cls, values: np.ndarray) -> Stats | None:
        if len(values) == 0:
            return None
        v = np.asarray(values, float)
        return cls(float(v.mean()), float(np.sqrt((v * v).mean())), float(v.max()))


@dataclass
class FollowTargetResult(SingleRunReport):
    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)  # of the --json report
    task: str
    robot: str
    arm: str
    motion: str
    orientation: str
    with_obstacle: bool
    obstacles: list[str]
    duration: float  # s
    control_rate: float  # Hz (actual: physics rate / substeps)
    safety_margin: float  # m
    settle_time: float  # s
    # "free": orientation error = angle between the tool axes (roll about it not counted); "symmetric": the
    # whole orientation is tracked, the target taken half-turned about the tool axis when nearer home
    tool_roll: str = "tracked"
    success: bool = False
    position_error_mm: Stats | None = None  # after settling
    orientation_error_deg: Stats | None = None
    final_position_error_mm: float = math.nan  # residual, mean of the last FINAL_WINDOW
    final_orientation_error_deg: float = math.nan
    reached: bool = False
    unreachable_reason: str | None = None
    min_clearance_mm: float | None = None  # robot–obstacle, PyBullet closest points (None: no obstacle)
    min_clearance_link: str | None = None
    min_clearance_obstacle: str | None = None
    contacts: int = 0  # robot–obstacle contact events (steps entering contact)
    contact_steps: int = 0  # control steps with robot–obstacle penetration
    environment_contact_steps: int = 0  # control steps with robot–ground/table/pedestal penetration
    step_time_median_ms: float = math.nan  # controller wall time per control step
    step_time_p95_ms: float = math.nan
    step_cpu_median_ms: float = math.nan  # CPU time per control step (unaffected by other processes)
    step_cpu_p95_ms: float = math.nan
    steps: int = 0
    soft_steps: int = 0  # steps solved with relaxed collision constraints
    fallback_steps: int = 0  # steps where the QP failed: zero velocity commanded
    escapes: int = 0  # local-minimum escapes started
    blocked_time: float = 0.0  # s spent at the safety margin (model distance) while off target
    collision_pairs: int = 0
    samples: list[tuple[float, float, float, float | None]] = field(default_factory=list)  # (t s, pos mm, rot deg, clearance mm)
    warnings: list[str] = field(default_factory=list)
    failed_phase: str | None = None
    reason: str | None = None
    sim_time: float = 0.0
    wall_time: float = 0.0
    record: str | None = None
    plot: str | None = None
    interrupted: bool = False  # stopped by SIGINT/SIGTERM: statistics over the steps run until then


    def summary_line(self, timing: object = None) -> str:
        if not self.success:
            return f"failed: {self.failed_phase}: {self.reason}"
        e = self.position_error_mm
        track = "no samples after settling" if e is None else f"RMS {e.rms:.2f} mm (max {e.max:.2f})"
        clear = "" if self.min_clearance_mm is None else f", min clearance {self.min_clearance_mm:.1f} mm, {self.contacts} contacts"
        head = "ok" if self.reached else "not reached"
        return (f"{head}: {self.robot} {self.motion} target: {track}, final {self.final_position_error_mm:.2f} mm / "
                f"{self.final_orientation_error_deg:.3f} deg{clear}, step {self.step_time_median_ms:.2f} ms median")

    def view(self, timing: object = None) -> ReportView:
        def stats(s: Stats | None, u: str, d: int) -> str:
            return "—" if s is None else f"mean {s.mean:.{d}f}, RMS {s.rms:.{d}f}, max {s.max:.{d}f} {u}"

        rows = [
            (f"position error (after {self.settle_time:g} s)", stats(self.position_error_mm, "mm", 2)),
            (f"{'tool-axis' if self.tool_roll == 'free' else 'orientation'} error (after {self.settle_time:g} s)",
             stats(self.orientation_error_deg, "deg", 3)),
            ("final error (residual)", f"{self.final_position_error_mm:.3f} mm / {self.final_orientation_error_deg:.4f} deg"),
            ("reached", "yes" if self.reached else f"no ({self.unreachable_reason})"),
        ]
        if self.obstacles:
            clear = "—" if self.min_clearance_mm is None else f"{self.min_clearance_mm:.2f} mm"
            rows += [("obstacles", ", ".join(self.obstacles)),
                     ("min robot–obstacle clearance", f"{clear} ({self.min_clearance_link} ↔ "
                                                      f"{self.min_clearance_obstacle}; margin {self.safety_margin * 1000:.0f} mm)"),
                     ("robot–obstacle contacts", f"{self.contacts} ({self.contact_steps} control steps)")]
        rows += [
            ("robot–ground/table contact steps", str(self.environment_contact_steps)),
            ("control step (median / p95)", f"{self.step_time_median_ms:.3f} / {self.step_time_p95_ms:.3f} ms "
                                            f"at {self.control_rate:.0f} Hz, {self.collision_pairs} collision pairs"),
            ("QP relaxed / failed steps", f"{self.soft_steps} / {self.fallback_steps} of {self.steps}"),
            ("local-minimum escapes", str(self.escapes)),
            ("simulated / wall time", f"{self.sim_time:.2f} s / {self.wall_time:.2f} s"),
        ]
        rows += [(k, v) for k, v in (("plot", self.plot), ("record", self.record)) if v]
        title = (f"run follow-target: {self.robot} ({self.motion} target, {self.orientation} orientation"
                 f"{', with obstacle' if self.with_obstacle else ''})")
        if not self.success:
            return ReportView(title, rows, warnings=list(self.warnings), status="failed",
                              status_text=f"{self.failed_phase}: {self.reason}")
        return ReportView(title, rows, warnings=list(self.warnings), status="ok" if self.reached else "warn",
                          status_text="" if self.reached else "target not reached")


def summarise(result: FollowTargetResult, series: list[tuple[float, float, float, float]], times: list[float],
               cpu: list[float], params: FollowTargetParams, ctrl: Any) -> None:
    result.steps = len(times)
    result.soft_steps, result.fallback_steps, result.escapes = ctrl.soft_steps, ctrl.fallbacks, ctrl.escape.count
    if times:
        ms = np.asarray(times) * 1000
        result.step_time_median_ms = float(np.median(ms))
        result.step_time_p95_ms = float(np.percentile(ms, 95))
        ms = np.asarray(cpu) * 1000
        result.step_cpu_median_ms = float(np.median(ms))
        result.step_cpu_p95_ms = float(np.percentile(ms, 95))
    if not series:
        return
    a = np.asarray(series, float)
    t, pos, rot = a[:, 0], a[:, 1], a[:, 2]
    settled = t >= params.settle_time
    result.position_error_mm = Stats.of(pos[settled] * 1000)
    result.orientation_error_deg = Stats.of(np.degrees(rot[settled]))
    final = t >= t[-1] - FINAL_WINDOW
    result.final_position_error_mm = float(pos[final].mean() * 1000)
    result.final_orientation_error_deg = float(np.degrees(rot[final].mean()))
    every = max(1, round(1.0 / (SAMPLE_RATE * (t[1] - t[0])))) if len(t) > 1 else 1
    result.samples = [(round(float(r[0]), 4), round(float(r[1]) * 1000, 3), round(math.degrees(r[2]), 4),
                       None if math.isinf(r[3]) else round(float(r[3]) * 1000, 2)) for r in a[::every]]
    result.reached, result.unreachable_reason = _reached(result, params, ctrl)


def _reached(result: FollowTargetResult, params: FollowTargetParams, ctrl: Any) -> tuple[bool, str | None]:
    """Reached: a target at rest at the end (static, waypoints) is within tolerance over the last
    FINAL_WINDOW; a moving one is tracked with RMS error within tolerance after settling."""
    from robocfg.motion.targets import TargetMotion

    at_rest = TargetMotion(params.motion).end_time <= params.duration - FINAL_WINDOW
    if at_rest:
        pos, rot = result.final_position_error_mm, result.final_orientation_error_deg
    elif result.position_error_mm is not None and result.orientation_error_deg is not None:
        pos, rot = result.position_error_mm.rms, result.orientation_error_deg.rms
    else:
        return False, "the run ended before the settle time"
    if pos <= params.reach_tolerance * 1000 and rot <= math.degrees(params.orientation_tolerance):
        return True, None
    if result.blocked_time > 0:
        return False, f"blocked by the environment for {result.blocked_time:.2f} s (held at the safety margin)"
    if ctrl.fallbacks:
        return False, f"the QP failed on {ctrl.fallbacks} step(s)"
    return False, "outside the workspace (or at a joint limit) for this orientation"


def plot_series(path: Path, series: list[tuple[float, float, float, float]], result: FollowTargetResult,
                params: FollowTargetParams) -> Path:
    """Tracking errors (own log axes) and clearance against time, as a PNG at ``path``
    (:mod:`robocfg.motion.plot_tracking`)."""
    from robocfg.motion.plot_tracking import TrackingSeries, plot_tracking

    title = f"{result.robot}: follow {result.motion} target" + (" with obstacle" if result.with_obstacle else "")
    return plot_tracking(path, TrackingSeries.from_rows(series), settle_time=result.settle_time,
                         position_tolerance=params.reach_tolerance, orientation_tolerance=params.orientation_tolerance,
                         safety_margin=result.safety_margin, title=title)


