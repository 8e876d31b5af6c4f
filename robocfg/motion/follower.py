"""Track a timed joint trajectory in the PyBullet world, one command per physics step.

PyBullet's position drive (``POSITION_CONTROL``, position gain kp, velocity gain kd = 1) sets the
joint velocity for the coming step to ``kd·q̇* + kp·(q* − q)/dt``, evaluated at the position
*before* the step, and then integrates ``q ← q + dt·q̇`` (semi-implicit Euler). Commanding the
reference at the *next* time (q*(t+dt), q̇*(t+dt)) therefore makes the arm lead the reference by
about one step (``dt·q̇``: 4 mm-rad at 1 rad/s and 240 Hz). The follower instead sends, at time t,
the position target q*(t) and the velocity feed-forward (q*(t+dt) − q*(t))/dt — the discrete
velocity that lands exactly on q*(t+dt) — so the only error left is what the drive's force cap
and the dynamics take away (``mode="matched"``). ``mode="next"`` is the naive variant, kept for
the benchmark.

Errors are measured after every step against the reference at the new time (rad or m).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robocfg.motion.trajectory import Trajectory


@dataclass
class Tracking:
    """Tracking errors per joint (arm order; rad or m) and the measured motion.

    ``final_error``: |q − q_end| at the step where the trajectory ends; ``settled_error``: after
    holding the last waypoint for ``settle_time`` s more.
    """

    joint_names: list[str]
    rms_error: list[float]
    max_error: list[float]
    final_error: list[float]
    settled_error: list[float]
    steps: int
    settle_time: float
    t: np.ndarray  # (N,) s since the start of the trajectory
    q: np.ndarray  # (N, n) measured positions

    @property
    def rms(self) -> float:
        """Largest per-joint RMS error."""
        return max(self.rms_error) if self.rms_error else 0.0

    @property
    def max(self) -> float:
        return max(self.max_error) if self.max_error else 0.0

    @property
    def final(self) -> float:
        return max(self.final_error) if self.final_error else 0.0

    @property
    def settled(self) -> float:
        return max(self.settled_error) if self.settled_error else 0.0


def follow(world, names: list[str], traj: Trajectory, settle_time: float = 0.25, mode: str = "matched",
           on_step: Callable[[], None] | None = None,
           command: Callable[[np.ndarray, np.ndarray], None] | None = None, lead: int = 0) -> Tracking:
    """Play ``traj`` on the world's first robot, joints ``names``; the robot should be at the
    trajectory's start. ``on_step`` runs after every physics step (e.g. a recorder); ``command(q,
    q̇)`` sends the targets (default: the robot's position drives of ``names``; an arm's
    ``command`` lets a dataset recording intercept them); ``lead``: send the reference that many
    physics steps ahead, for a ``command`` that delays by as much (a dataset's command gate: one
    frame), so the arm still follows the plan on time."""
    if mode not in ("matched", "next"):
        raise ValueError(f"unknown follower mode {mode!r}")
    robot, dt = world.robot, float(world.dt)
    send = command if command is not None else (lambda q, qd: robot.command_positions(names, q, qd))

    n_steps = int(np.ceil(traj.duration / dt - 1e-9))
    times = np.arange(n_steps + 1) * dt
    q_ref, qd_ref, _ = traj.evaluate(times)  # clipped to the end time
    ts, qs, errs = [0.0], [robot.joint_positions(names)], [robot.joint_positions(names) - q_ref[0]]
    for k in range(n_steps):
        j = k + lead  # k itself without a lead
        if j >= n_steps:  # led past the end: hold the last point
            send(q_ref[n_steps], np.zeros(len(names)))
        elif mode == "matched":
            send(q_ref[j], (q_ref[j + 1] - q_ref[j]) / dt)
        else:
            send(q_ref[j + 1], qd_ref[j + 1])
        world.step()
        if on_step is not None:
            on_step()
        q = robot.joint_positions(names)
        ts.append(times[k + 1])
        qs.append(q)
        errs.append(q - q_ref[k + 1])
    q_end = q_ref[-1]
    final = np.abs(qs[-1] - q_end)
    send(q_end, np.zeros(len(names)))
    for _ in range(round(settle_time / dt)):
        world.step()
        if on_step is not None:
            on_step()
    settled = np.abs(robot.joint_positions(names) - q_end)
    e = np.array(errs)
    return Tracking(list(names), np.sqrt(np.mean(e**2, axis=0)).tolist(), np.max(np.abs(e), axis=0).tolist(),
                    final.tolist(), settled.tolist(), n_steps, settle_time, np.array(ts), np.array(qs))
