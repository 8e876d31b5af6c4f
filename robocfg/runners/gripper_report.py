"""Typed result of ``run gripper``: the moves, the hold test and the measured widths (m, s)."""

from __future__ import annotations

from dataclasses import dataclass, field

from robocfg.engine.runner import ReportView, TableView
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION, SingleRunReport


@dataclass
class Move:
    """One close or open command."""

    phase: str
    cycle: int
    t_start: float  # s, simulated
    width_start: float | None  # m (None for suction)
    width_end: float | None  # m
    settle_time: float | None  # s from the command until the width stays within tolerance of width_end
    state_end: float  # 1.0 open / −1.0 closed
    mimic_max_error: float  # rad or m, worst follower error during the move


@dataclass
class HoldTest:
    object: str
    support_lowered_by: float  # m (0: support removed)
    grasping_before: bool  # both fingers touch the object after closing
    grasping_after: bool
    width_on_object: float | None  # m (None for suction)
    drop: float  # m the object sank while the support went away
    held: bool
    released: bool  # the object left the fingers after opening


@dataclass
class GripperResult(SingleRunReport):
    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)  # of the --json report
    task: str
    robot: str
    arm: str
    gripper_type: str
    mode: str
    dt: float
    cycles: int
    min_width: float
    max_width: float
    success: bool = False
    failed_phase: str | None = None
    reason: str | None = None
    samples: list[tuple[float, float | None]] = field(default_factory=list)  # (t s, measured width m)
    moves: list[Move] = field(default_factory=list)
    time_to_close: float | None = None  # s, worst over cycles
    time_to_open: float | None = None
    final_closed_width: float | None = None
    final_open_width: float | None = None
    width_change: float | None = None  # m, open − closed (free, last cycle)
    mimic_max_error: float = 0.0
    hold: HoldTest | None = None
    warnings: list[str] = field(default_factory=list)
    sim_time: float = 0.0
    wall_time: float = 0.0
    record: str | None = None
    interrupted: bool = False  # stopped by SIGINT/SIGTERM: the result holds what was measured until then


    def summary_line(self, timing: object = None) -> str:
        if not self.success:
            return f"failed: {self.failed_phase}: {self.reason}"
        held = "" if self.hold is None else f", {self.hold.object} {'held' if self.hold.held else 'NOT held'}"
        if self.gripper_type == "suction":
            released = "" if self.hold is None else f", {'released' if self.hold.released else 'NOT released'} when off"
            return f"ok: {self.robot} {self.gripper_type} gripper{held}{released}"
        return (f"ok: {self.robot} {self.gripper_type} gripper closed {_mm(self.final_closed_width)} in "
                f"{_s(self.time_to_close)}, open {_mm(self.final_open_width)} in {_s(self.time_to_open)}{held}")

    def view(self, timing: object = None) -> ReportView:
        rows = [
            ("time to close", _s(self.time_to_close)), ("time to open", _s(self.time_to_open)),
            ("final closed width", _mm(self.final_closed_width)), ("final open width", _mm(self.final_open_width)),
            ("width change", f"{_mm(self.width_change)} of {_mm(self.max_width - self.min_width)} configured"),
            ("mimic tracking error (max)", f"{self.mimic_max_error:.2e}"),
        ]
        if self.hold is not None:
            h = self.hold
            touching = "attached" if self.gripper_type == "suction" else "both fingers touching"
            rows += [("hold object", h.object), ("width on object", _mm(h.width_on_object)),
                     ("support lowered by", _mm(h.support_lowered_by) if h.support_lowered_by > 0 else "removed"),
                     ("held", f"{h.held} (sank {_mm(h.drop)}, {touching}: {h.grasping_after})"),
                     ("released on open", str(h.released))]
        rows.append(("simulated / wall time", f"{self.sim_time:.2f} s / {self.wall_time:.2f} s"))
        if self.record:
            rows.append(("record", self.record))
        moves = TableView("moves", ["phase", "cycle", "t start", "width start", "width end", "settled after", "state",
                                    "mimic err"],
                          [[m.phase, str(m.cycle), f"{m.t_start:.2f} s", _mm(m.width_start), _mm(m.width_end),
                            _s(m.settle_time), "open" if m.state_end > 0 else "closed", f"{m.mimic_max_error:.1e}"]
                           for m in self.moves])
        footer = []
        if self.samples and self.samples[0][1] is not None:
            picks = self.samples[::max(1, round(SAMPLE_EVERY / self.dt))]
            footer.append("width over time: " + "  ".join(f"{t:.2f}s {(w or 0.0) * 1000:.1f}" for t, w in picks) + " (mm)")
        return ReportView(f"run gripper: {self.robot} ({self.gripper_type}, {self.mode})", rows, tables=[moves],
                          warnings=list(self.warnings), footer=footer, status="ok" if self.success else "failed",
                          status_text="" if self.success else f"{self.failed_phase}: {self.reason}")


SAMPLE_EVERY = 0.25  # s between the width samples printed


def _mm(v: float | None) -> str:
    return "—" if v is None else f"{v * 1000:.1f} mm"


def _s(v: float | None) -> str:
    return "—" if v is None else f"{v:.3f} s"
