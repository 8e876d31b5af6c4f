"""The measuring harness of ``run gripper``: stepping the world while sampling the finger width
(m) every physics step, and one close/open measured as a :class:`Move` (start and end width, the
time the width took to settle, the worst mimic error). Times in s of simulated time.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from robocfg.config.commands import GripperParams
from robocfg.runners.gripper_report import GripperResult, Move

if TYPE_CHECKING:
    from robocfg.sim.record import Recorder

SETTLE_TIME = 0.25  # s
SETTLE_TOL_FRACTION = 0.02  # of max_width − min_width, at least SETTLE_TOL_MIN
SETTLE_TOL_MIN = 0.001  # m
SETTLE_TAIL = 0.1  # s the width must stay within tolerance to count as settled


class GripperRun:
    """One gripper run under way: steps the world, samples the finger width every step into the
    result, names phases for the recording, and measures each close/open as a :class:`Move`."""

    def __init__(self, world, params: GripperParams, result: GripperResult, recorder: Recorder | None,
                 arm: str | None):
        self.world, self.params, self.result, self.recorder = world, params, result, recorder
        self.arm = world.robot.arm(arm)
        self.gripper = self.arm.gripper

    def width(self) -> float | None:
        return self.gripper.width()

    def phase(self, name: str) -> None:
        """Name the phase under way (recordings label their frames with it)."""
        if self.recorder is not None:
            self.recorder.set_phase(name)

    def run_for(self, seconds: float, each: Callable[[], None] | None = None) -> float:
        """Step for ``seconds``; returns the worst mimic error seen."""
        w, worst = self.world, 0.0
        mimic = w.robot.mimic
        for _ in range(max(1, round(seconds / w.dt))):
            w.step()
            if each is not None:
                each()
            self.result.samples.append((round(w.t, 6), self.width()))
            if mimic is not None and mimic.pairs:
                worst = max(worst, mimic.max_error())
            if self.recorder is not None:
                self.recorder.maybe_capture()
        self.result.mimic_max_error = max(self.result.mimic_max_error, worst)
        return worst

    def move_time(self) -> float:
        """Time given to one close/open: ``hold_time``, plus the target ramp in smooth mode."""
        ramp = 1.0 / self.params.rate if self.params.mode == "smooth" and not self.gripper.grasps_at_surface else 0.0
        return self.params.hold_time + ramp

    def move(self, phase: str, cycle: int, command: Callable[[], None]) -> Move:
        w, g = self.world, self.gripper
        t0, k0 = w.t, len(self.result.samples)
        w_start = self.width()
        self.phase(phase if self.params.cycles == 1 or phase not in ("close", "open") else f"{phase} {cycle + 1}")
        command()
        err = self.run_for(self.move_time())
        widths = [s[1] for s in self.result.samples[k0:]]
        w_end, settle = widths[-1], None
        if w_end is not None:
            travel = self.result.max_width - self.result.min_width
            tol = max(SETTLE_TOL_MIN, SETTLE_TOL_FRACTION * travel)
            outside = [k for k, v in enumerate(widths) if v is None or abs(v - w_end) > tol]
            if not outside:
                settle = w.dt
            elif (len(widths) - 1 - outside[-1]) * w.dt >= SETTLE_TAIL:
                settle = (outside[-1] + 1) * w.dt
        m = Move(phase, cycle, t0, w_start, w_end, settle, g.state(), err)
        self.result.moves.append(m)
        return m
