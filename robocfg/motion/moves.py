"""Arm moves shared by the grasping runners: IK to EE poses (continuous along straight lines),
min-jerk timing, trajectory following, convergence checks, and close-until-held.

Used by pick-place and grasp: ``ArmMover.move(T_goal, straight=...)`` plans joint waypoints along
a straight EE line, as few as keep the played path on the line by FK (``robocfg.motion.straight_line``;
or, for a joint-space move, the IK answer nearest the current joints), times them with ``MinJerkPath``, sends position + velocity targets every
physics step, and waits until the EE is within tolerance (``move_reactive`` instead steps a
follow-target controller that avoids the scene, with the same checks). Failures raise
``MoveFailed(phase, reason)``. Poses are world_T_ee (4x4, m).

IK is bounded by an iteration budget (``bound_ik_by_iterations``) rather than wall-clock time, so
the same seed gives the same answers whatever the machine load; ``ik_budget`` (s) bounds a model
that has no iteration budget only.

Over 300 lines: one class whose moves, polls and gripper waits share the mover's state; the lines,
the timing and the held-load bound live in their own modules.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from robocfg.errors import PhaseFailed
from robocfg.motion.joint_travel import joint_travel
from robocfg.motion.minjerk_path import JointSpline, MinJerkPath
from robocfg.motion.pose_goal import PoseGoal

if TYPE_CHECKING:
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.limits import JointLimits
    from robocfg.motion.straight_line import Fail, Plan, Solve, Unreachable
    from robocfg.motion.trajectory import Trajectory
    from robocfg.sim.gripper.base import Gripper
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World

SETTLE_POLL = 4  # physics steps between convergence checks
DIRECT_TRAVEL_CHECK = 1.0  # rad: a point-to-point IK answer this far away is compared with a continuous one
TIMEOUT_FACTOR = 1.25  # a move without a fixed timeout may take its planned duration × this ...
TIMEOUT_MARGIN = 1.0  # ... + this many seconds (s) to settle and converge
UNPLANNED_TIMEOUT = 4.0  # s: the limit of a move that has no plan to measure (convergence only)
REACTIVE_DETOUR = 2.0  # a reactive move may take this many times the direct move (it goes round obstacles)
IK_ITERATIONS = 400  # LM iterations per IK query over all restarts (see bound_ik_by_iterations)


def bound_ik_by_iterations(model: KinematicModel, iterations: int = IK_ITERATIONS) -> None:
    """Make ``model``'s IK solver stop after ``iterations`` iterations (all restarts included),
    never by its time budget (which it then ignores): every backend honours the budget, so the
    answers do not depend on the machine's speed or load."""
    model.solver().max_total_iter = iterations


MoveFailed = PhaseFailed  # the name the motion code raises; one (phase, reason) error for all


def grasp_hint(arm: ArmHandle, width: float | None) -> str:
    """The likely cause of a grasp that does not hold, for a failure message ("" when none can be
    named): fingers closed on nothing or the object slipped, and ``tcp_offset`` against the finger
    pads measured from the URDF (``robocfg.checks.tool_point.grasp_failure_hint``)."""
    from robocfg.assets.paths import Resolver
    from robocfg.checks.tool_point import grasp_failure_hint

    checked = arm.robot.checked
    return grasp_failure_hint(checked.urdf, Resolver(checked.path.parent, checked.config.package_dirs), arm.config,
                              checked.gripper_joints(arm.config), width)


@dataclass
class ArmMover:
    """Moves one arm of ``world``. ``model``: KinematicModel of the arm; ``limits``: JointLimits
    for timing; tolerances in m and rad; ``timeout`` (s) per move, or None: each move may take its
    planned duration × ``TIMEOUT_FACTOR`` + ``TIMEOUT_MARGIN`` (a slow arm is slow, not failed); ``on_step`` after every physics
    step (e.g. a recorder); ``phase`` names the current phase in failures."""

    world: World
    arm: ArmHandle
    model: KinematicModel
    limits: JointLimits
    position_tolerance: float = 0.005
    orientation_tolerance: float = 0.05
    timeout: float | None = 4.0
    on_step: Callable[[], None] | None = None
    phase: str = "move"
    ik_budget: float = 1.0  # s of wall clock per IK query, for a model without bound_ik_by_iterations
    max_acceleration: float | None = None  # m/s²: the EE's peak acceleration in a timed move (a held load), None: free
    _answers: dict[tuple[bytes, bytes], IKResult] = field(default_factory=dict, init=False, repr=False)  # see ik()
    _lines: dict[bytes, Plan] = field(default_factory=dict, init=False, repr=False)  # see straight_path()

    def ik(self, T: np.ndarray, seed: np.ndarray) -> IKResult:
        """IK of the EE pose ``T`` (4x4, world) from ``seed`` (rad or m), remembered for the mover's
        life (one episode) under the exact bytes of both: the grasp choice and the moves after it
        ask some of the same questions (the pre-grasp pose from the same joints), and the solver's
        answer depends on nothing else (an iteration budget, a fixed restart seed). The waypoints
        of straight lines are solved directly (each from its neighbour: never asked twice)."""
        T, seed = np.asarray(T, dtype=float), np.asarray(seed, dtype=float)
        key = (T.tobytes(), seed.tobytes())
        res = self._answers.get(key)
        if res is None:
            res = self._answers[key] = self.model.ik(T, seed_q=seed, frame="ee", time_budget=self.ik_budget)
        out = object.__new__(type(res))  # copy.copy's shallow copy, without its reduce protocol:
        out.__dict__.update(res.__dict__)  # callers may keep or change their copy
        out.q = res.q.copy()
        return out

    def solve(self, T: np.ndarray, seed: np.ndarray, what: str = "") -> np.ndarray:
        res = self.ik(T, seed)
        if not res.converged:
            raise self._unreachable(res, what)
        return res.q

    def _unreachable(self, res, what: str) -> MoveFailed:
        return MoveFailed(self.phase, f"unreachable{what} (residual {res.pos_err * 1000:.1f} mm, "
                                      f"{math.degrees(res.rot_err):.1f}°)")

    def straight_waypoints(self, q0: np.ndarray, T_goal: np.ndarray) -> np.ndarray:
        """Joint waypoints (k, n) along the straight EE line from FK(q0) to ``T_goal`` (orientation
        of the goal) whose played path stays on the line (:mod:`robocfg.motion.straight_line`)."""
        return self.straight_path(q0, T_goal)[0]

    def straight_path(self, q0: np.ndarray, T_goal: np.ndarray) -> tuple[np.ndarray, JointSpline]:
        """:meth:`straight_waypoints` and the joint path through them (for ``MinJerkPath``). The
        episode's last line to the same ``T_goal`` (exact bytes) is checked from ``q0`` first and
        kept if it passes (:func:`~robocfg.motion.straight_line.straight_line_plan`): the grasp
        choice checks the approach from the pre-grasp answer, the approach then starts where the
        pre-grasp move converged."""
        from robocfg.motion.straight_line import straight_line_plan

        key = np.asarray(T_goal, dtype=float).tobytes()
        W, path, self._lines[key] = straight_line_plan(self.model, q0, T_goal, *self._line_calls(),
                                                       earlier=self._lines.get(key))
        return W, path

    def straight_end(self, q0: np.ndarray, T_goal: np.ndarray) -> np.ndarray:
        """Where a straight line from FK(q0) to ``T_goal`` would end, without building and checking
        the line (:func:`~robocfg.motion.straight_line.straight_line_end`): a joint-space goal on q0's branch.
        Its IK goes through :meth:`ik`'s remembered answers: where the orientation need not turn
        first, its one solve is the goal from q0, the question :meth:`move` has just asked."""
        from robocfg.motion.straight_line import straight_line_end

        return straight_line_end(self.model, q0, T_goal, *self._line_calls(self.ik))

    def _line_calls(self, ik: Solve | None = None) -> tuple[Solve, Fail, Unreachable]:
        """(IK, failure, unreachable) for the straight-line functions. IK (``ik`` None) goes
        straight to the solver, not through the answers remembered by self.ik: the points of a
        line are asked from the line's own seeds, never twice in an episode."""
        if ik is None:
            solve, budget = self.model.ik, self.ik_budget
            ik = lambda T, seed: solve(T, seed_q=seed, frame="ee", time_budget=budget)  # noqa: E731
        return ik, lambda reason: MoveFailed(self.phase, reason), self._unreachable

    def move(self, T_goal: np.ndarray, straight: bool, q_goal: np.ndarray | None = None,
             check: Callable[[], str | None] | None = None) -> None:
        """Go to ``T_goal``; ``q_goal`` (a known IK answer) skips the IK of a joint-space move.
        A joint-space move takes, of the direct IK answer and where a straight line would end
        (:meth:`straight_end`), the one with less joint travel (IK may land on a far branch).
        ``check()`` runs at the end and returns a failure reason or None."""
        q0 = self.arm.joint_positions()
        path = None
        if straight:
            W, spline = self.straight_path(q0, T_goal)
            path = (W, spline)
        else:
            if q_goal is None:
                q_goal = self.solve(T_goal, q0)
                if joint_travel(q0, q_goal) > DIRECT_TRAVEL_CHECK:
                    try:
                        q_line = self.straight_end(q0, T_goal)
                        if joint_travel(q0, q_line) < joint_travel(q0, q_goal):
                            q_goal = q_line
                    except MoveFailed:
                        pass
            W = np.asarray([q0, q_goal])
        if joint_travel(W[0], W[-1]) >= 1e-6:
            traj = MinJerkPath(W, self.limits, path=path)
            if self.max_acceleration is not None:
                traj.duration *= self._stretch(traj, self.max_acceleration)
            if self.timeout is not None and traj.duration > self.timeout:
                raise MoveFailed(self.phase, f"motion needs {traj.duration:.2f} s, more than the {self.timeout:.2f} s timeout")
            t_start = self.world.t
            self.play(traj)
            self.converge(T_goal, t_start, self.time_limit(traj.duration))
        if check is not None:
            reason = check()
            if reason:
                raise MoveFailed(self.phase, reason)

    def move_reactive(self, T_goal: np.ndarray, drive, check: Callable[[], str | None] | None = None) -> None:
        """Go to ``T_goal`` driven by the follow-target controller of ``drive`` (a
        :class:`~robocfg.motion.reactive_drive.ReactiveDrive`), which keeps the arm clear of the
        scene; same convergence tolerances, ``timeout`` and ``check()`` as :meth:`move`."""
        ctrl, T_tcp = drive.controller, T_goal @ drive.T_ee_tcp
        limit = self.time_limit(self._direct_duration(T_goal), REACTIVE_DETOUR)
        ctrl.reset(self.arm.joint_positions())
        t_start, still = self.world.t, np.zeros(6)
        goal = PoseGoal(T_goal, self.position_tolerance, self.orientation_tolerance)
        while True:
            pos, quat = self.arm.ee_position_quat()
            if goal.reached(pos, quat):
                break
            if self.world.t - t_start > limit:
                raise self._not_converged(goal, pos, quat, limit)
            res = ctrl.step(T_tcp, q_measured=self.arm.joint_positions(), velocity=still)
            self.arm.command(res.q, res.dq)
            self.step(drive.substeps)
        self.arm.command(ctrl.q, np.zeros_like(ctrl.q))  # hold where the controller stopped
        if check is not None:
            reason = check()
            if reason:
                raise MoveFailed(self.phase, reason)

    def slowed_for_load(self, traj: Trajectory) -> Trajectory:
        """``traj`` slowed uniformly (same path) so that the EE's peak acceleration stays within
        ``max_acceleration`` (what the grip carries); ``traj`` itself when that is None or already met."""
        from robocfg.motion.trajectory import Slowed

        if self.max_acceleration is None or traj.duration <= 0:
            return traj
        k = self._stretch(traj, self.max_acceleration)
        return traj if k <= 1.0 else Slowed(traj, k)

    def _stretch(self, traj, a_max: float) -> float:
        """Factor (≥ 1) by which to slow ``traj`` so that the EE's peak acceleration stays within
        ``a_max`` (m/s²; :func:`robocfg.motion.ee_acceleration.stretch_factor`): time scaled by c
        scales accelerations by 1/c²."""
        from robocfg.motion.ee_acceleration import stretch_factor

        return stretch_factor(self.model, traj, a_max)

    def play(self, traj) -> None:
        """Send the trajectory's position and velocity targets every physics step (no tracking
        statistics, so the per-step cost stays at one motor call)."""
        dt = self.world.dt
        n = math.ceil(traj.duration / dt - 1e-9)
        q_ref, qd_ref = traj.step_targets(dt, n)
        self.world.play(self.arm, q_ref, qd_ref, self.on_step)

    def time_limit(self, planned: float | None, factor: float = 1.0) -> float:
        """Time (s) a move may take: the fixed ``timeout``, else the planned duration (s) ×
        ``factor`` × ``TIMEOUT_FACTOR`` + ``TIMEOUT_MARGIN`` (settling and convergence)."""
        if self.timeout is not None:
            return self.timeout
        if planned is None:
            return UNPLANNED_TIMEOUT
        return planned * factor * TIMEOUT_FACTOR + TIMEOUT_MARGIN

    def _direct_duration(self, T_goal: np.ndarray) -> float | None:
        """Duration (s) of the direct joint-space move to ``T_goal`` (None when IK fails): the
        yardstick for a reactive move's time limit."""
        if self.timeout is not None:
            return None
        q0 = self.arm.joint_positions()
        res = self.ik(T_goal, q0)
        if not res.converged or np.max(np.abs(res.q - q0)) < 1e-6:
            return None
        return float(MinJerkPath(np.asarray([q0, res.q]), self.limits).duration)

    def converge(self, T_goal: np.ndarray, t_start: float, limit: float | None = None) -> None:
        """Poll every ``SETTLE_POLL`` steps until the EE is within tolerance of ``T_goal``
        (:class:`~robocfg.motion.pose_goal.PoseGoal`); ``MoveFailed`` once ``limit`` s have passed
        since ``t_start``."""
        limit = self.time_limit(None) if limit is None else limit
        goal = PoseGoal(T_goal, self.position_tolerance, self.orientation_tolerance)
        while True:
            pos, quat = self.arm.ee_position_quat()
            if goal.reached(pos, quat):
                return
            if self.world.t - t_start > limit:
                raise self._not_converged(goal, pos, quat, limit)
            self.step(SETTLE_POLL)

    def _not_converged(self, goal: PoseGoal, pos, quat, limit: float) -> MoveFailed:
        dp, dr = goal.errors_at(pos, quat)
        return MoveFailed(self.phase, f"did not converge within {limit:.1f} s "
                                      f"(error {dp * 1000:.1f} mm, {math.degrees(dr):.1f}°)")

    def close_until_held(self, body: int, timeout: float) -> None:
        """Close the gripper; wait until both fingers touch ``body`` and the measured width is still
        for 0.1 s (or ``timeout`` s pass: then it must at least be held)."""
        g = self._gripper()
        t0 = self.world.t
        g.close()
        last = g.width()  # None: no fingers whose stillness could be awaited (suction)
        still = 0.0
        # the cheap test first: the contact query (a pure read of the last step's contacts) only
        # once the width has been still long enough, where its answer decides
        while not ((last is None or still >= 0.1) and g.is_grasping(body)):
            self.step(SETTLE_POLL)
            w = g.width()
            if w is not None and last is not None:
                still = still + SETTLE_POLL * self.world.dt if abs(w - last) < 2e-4 else 0.0
            last = w
            if self.world.t - t0 > timeout:
                if g.is_grasping(body):
                    return
                width = f" (width {w * 1000:.1f} mm)" if w is not None else ""
                hint = grasp_hint(self.arm, w)
                raise MoveFailed(self.phase, f"the object is not held{width}" + (f"; {hint}" if hint else ""))

    def _gripper(self) -> Gripper:
        if self.arm.gripper is None:
            raise MoveFailed(self.phase, f"arm {self.arm.config.name!r} has no gripper")
        return self.arm.gripper

    def open_gripper(self, seconds: float = 0.4) -> None:
        self._gripper().open()
        self.settle(seconds)

    def step(self, n: int) -> None:
        """``n`` physics steps, ``on_step`` after each (none: the world's own loop, bare while idle)."""
        if self.on_step is None:
            self.world.step(n)
            return
        for _ in range(n):
            self.world.step()
            self.on_step()

    def settle(self, seconds: float) -> None:
        self.step(round(seconds / self.world.dt))
