"""The command gate: what the recorded actions are, and the only commands that reach the robot.

While an episode is recorded (or replayed) the runner's arm and gripper commands do not go to the
drives directly: the gate keeps the latest one, and at each dataset frame k (every
``steps_per_frame`` physics steps) *latches* it as action k. Over the next interval the arm's
position targets ramp linearly from action k - 1 to action k (target velocity = the ramp's slope)
and the gripper command of action k is applied at once. Replay latches the recorded actions
instead of the runner's, so recording and replay send identical motor commands.

The price is a lag of one frame (50 ms at 20 Hz) between what the runner asks for and what the
drives get; the runner's moves wait for convergence, so phases take slightly longer but succeed
as before. Actions are rounded to float32 before use, as stored.
"""

from __future__ import annotations

import numpy as np

OPEN, CLOSE = 1.0, -1.0


class CommandGate:
    """Intercepts ``arm.command`` and ``arm.gripper.open/close`` of one arm (see module doc)."""

    def __init__(self, world, arm, steps_per_frame: int):
        self.world, self.arm, self.gripper = world, arm, arm.gripper
        self.steps_per_frame = steps_per_frame
        drives = arm.robot.drives
        self.q_wanted: np.ndarray | list[float] = np.array([drives[j].target if j in drives else q
                                  for j, q in zip(arm.joints, arm.joint_positions(), strict=True)])
        self.g_wanted = OPEN
        self._g_applied = OPEN  # a restored world starts with the gripper reset open
        self._prev = self._cur = self._round(np.append(self.q_wanted, OPEN))
        self._steps = np.arange(1, steps_per_frame + 1)[:, None] / steps_per_frame  # ramp fractions (n, 1)
        # the current interval's arm targets for its steps 1..n (rad), their slope (rad/s), and
        # whether they move (a held target is sent once per interval); set by ``latch``
        self.ramp: list[list[float]] = []
        self.slope: list[float] = []
        self.moving = False
        self._interval = steps_per_frame * world.dt  # s between frames
        self._a = np.empty(len(arm.joints) + 1, np.float32)  # action k, filled in place
        self._real_command = arm.command
        self._real_open = getattr(self.gripper, "open", None)
        self._real_close = getattr(self.gripper, "close", None)

    # ---- interception ------------------------------------------------------------------------
    def install(self) -> None:
        self.arm.command = self._want_arm
        if self.gripper is not None:
            self.gripper.open = lambda: self._want_gripper(OPEN)
            self.gripper.close = lambda: self._want_gripper(CLOSE)

    def remove(self) -> None:
        self.arm.__dict__.pop("command", None)
        if self.gripper is not None:
            self.gripper.__dict__.pop("open", None)
            self.gripper.__dict__.pop("close", None)

    def _want_arm(self, q, velocities=None) -> None:
        # a list (a trajectory converted once) is kept as it is; an array is copied (callers reuse theirs)
        self.q_wanted = q if type(q) is list else np.array(q, dtype=float)

    def _want_gripper(self, g: float) -> None:
        self.g_wanted = g

    # ---- frames ------------------------------------------------------------------------------
    def latch(self, action: np.ndarray | None = None, first: bool = False) -> np.ndarray:
        """Take action k (the runner's latest wish, or ``action`` on replay); returns it (float64
        values exactly representable in float32)."""
        if action is None:
            buf = self._a
            buf[:-1] = self.q_wanted
            buf[-1] = self.g_wanted
            a = buf.astype(np.float64)
        else:
            a = self._round(action)
        self._prev, self._cur = (a if first else self._cur), a
        prev = self._prev[:-1]
        delta = a[:-1] - prev
        # the interval's targets, computed once: the drives' per-step path then only sends them
        self.ramp = (prev + self._steps * delta).tolist()
        self.slope = (delta / self._interval).tolist()
        self.moving = bool(delta.any())
        g = float(a[-1])
        real = self._real_open if g > 0 else self._real_close
        if g != self._g_applied and real is not None:
            real()
            self._g_applied = g
        return a

    def drive(self, j: int) -> None:
        """Send the arm targets for physics step ``j`` (1..steps_per_frame) of the current interval."""
        if j > 1 and not self.moving:  # a held target is sent once per interval, not every step
            return
        self._real_command(self.ramp[min(j, self.steps_per_frame) - 1], self.slope)

    @staticmethod
    def _round(a: np.ndarray) -> np.ndarray:
        return np.asarray(a, dtype=np.float32).astype(np.float64)
