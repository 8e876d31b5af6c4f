"""The global planner for free-space moves: collision-free joint path, shortened, then timed.

``JointPlanner.plan(q_start, q_goal)``:

1. both ends must be valid for the :class:`CollisionChecker` (otherwise the failure names the
   colliding pair);
   (a goal joint that can turn more than a revolution is first moved by whole turns next to the
   start's value: the same pose, a much shorter path; the path's last waypoint is that goal);
2. the straight joint-space segment is tried first (most free-space moves need nothing more);
3. otherwise OMPL RRT-Connect (:mod:`.rrt`) within the budget;
4. the path is shortened (:mod:`.shortcut`), every segment still checked.

:func:`JointPlanner.timed` turns the path into a trajectory with toppra (through
:func:`robocfg.motion.plan.plan_trajectory`, on a grid of 10 points a segment, at least 30:
``PlannerSettings.gridpoints_per_segment``, ``min_gridpoints``; a single straight segment gets the synchronised
trapezoid, time-optimal along a line, without toppra) and checks the *timed* path too: a spline through the
waypoints can cut a corner the straight segments went around; if any sample of it is invalid, the
path is timed with a stop at every waypoint instead (straight segments: exactly what was checked).

The budget is given in milliseconds and enforced as a number of collision checks (``budget_ms`` ×
``checks_per_ms``), so a search ends at the same point on a loaded or an idle machine and the same
query gives the same answer (``wall_factor`` is kept for settings files; the wall clock ends no search).
Joint values in rad (arm order), lengths in rad (Euclidean joint space).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from robocfg.errors import RobocfgError
from robocfg.planning.checker import CollisionChecker
from robocfg.planning.rrt import RRTSettings, rrt_connect
from robocfg.planning.shortcut import path_length, shortcut

if TYPE_CHECKING:
    from robocfg.motion.limits import JointLimits
    from robocfg.motion.plan import Plan


class PlanningFailed(RobocfgError):
    """No collision-free path: ``reason`` is one line (``no collision-free path found in 500 ms``)."""

    def __init__(self, reason: str):
        self.reason = reason
        super().__init__(reason)


@dataclass(frozen=True)
class PlannerSettings:
    resolution: float = 0.02  # rad: spacing of the checked states along every segment
    budget_ms: float = 1000.0  # search budget per query (as collision checks, see the module doc)
    checks_per_ms: float = 40.0  # nominal checks per ms (≈ 25 µs per check for a 7-DoF arm)
    wall_factor: float = 10.0  # the wall-clock safety net is budget_ms × this (a loaded machine is slow)
    range: float = 1.0  # rad: longest RRT extension (measured best of 0.7–2 in a shelf; OMPL: 20 % of the box diagonal)
    shortcut_attempts: int = 15
    seed: int = 0  # random shortcuts
    # toppra grid of a planned path: this many points a segment, at least ``min_gridpoints`` (a
    # planned path has 2–5 segments; toppra's default 100 points cost 6.2 ms a transport on the
    # obstacle task, 30 cost 3.2 ms and lengthen the motion by 0.6 %, 20 episodes)
    gridpoints_per_segment: int = 10
    min_gridpoints: int = 30


@dataclass(frozen=True)
class PlannedPath:
    """A collision-free polyline in joint space and how it was found."""

    waypoints: np.ndarray  # (k, n) rad, first = start, last = goal
    method: Literal["direct", "rrt_connect"]
    raw_length: float  # rad, before shortening
    length: float  # rad
    checks: int  # collision checks used (search + shortening)
    seconds: float  # wall clock of the whole query
    cpu_seconds: float  # CPU time of this thread for the whole query (insensitive to other processes)


class JointPlanner:
    """Plans for one arm: ``checker`` (its collision model and scene), joint box ``lower``/``upper``."""

    def __init__(self, checker: CollisionChecker, lower: np.ndarray, upper: np.ndarray,
                 settings: PlannerSettings = PlannerSettings()):
        self.checker, self.settings = checker, settings
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)

    def _rrt_settings(self) -> RRTSettings:
        s = self.settings
        return RRTSettings(resolution=s.resolution, range=s.range, max_checks=int(s.budget_ms * s.checks_per_ms),
                           budget=s.budget_ms * s.wall_factor / 1000.0)

    def check_state(self, q: np.ndarray, what: str) -> None:
        """Raise PlanningFailed naming the colliding pairs if ``q`` is not valid."""
        if not self.checker.is_valid(q):
            hits = self.checker.contacts(q)
            detail = ", ".join(c.describe() for c in hits[:3]) or "a pair closer than the margin"
            raise PlanningFailed(f"the {what} is in collision ({detail}, margin {self.checker.margin * 1000:.0f} mm)")

    def plan(self, q_start: np.ndarray, q_goal: np.ndarray) -> PlannedPath:
        """A collision-free path from ``q_start`` to ``q_goal``; raises PlanningFailed."""
        t0, c0, cpu0 = time.perf_counter(), self.checker.checks, time.thread_time()
        qs = np.asarray(q_start, float)
        qg = self.nearest_turn(np.asarray(q_goal, float), qs)
        s = self.settings
        self.check_state(qs, "start configuration")
        self.check_state(qg, "goal configuration")
        if self.checker.segment_valid(qs, qg, s.resolution):
            P = np.vstack([qs, qg])
            return PlannedPath(P, "direct", path_length(P), path_length(P), self.checker.checks - c0,
                               time.perf_counter() - t0, time.thread_time() - cpu0)
        lo, hi = self.search_box(qs, qg)
        res = rrt_connect(self.checker, qs, qg, lo, hi, self._rrt_settings())
        if res.path is None:
            raise PlanningFailed(f"no collision-free path found in {s.budget_ms:.0f} ms "
                                 f"({res.checks} collision checks{', wall-clock limit hit' if res.stopped_by == 'budget' else ''})")
        rng = np.random.default_rng([s.seed, 0x5C])
        P = shortcut(res.path, self.checker, s.resolution, rng, s.shortcut_attempts)
        return PlannedPath(P, "rrt_connect", path_length(res.path), path_length(P), self.checker.checks - c0,
                           time.perf_counter() - t0, time.thread_time() - cpu0)

    def nearest_turn(self, q: np.ndarray, near: np.ndarray) -> np.ndarray:
        """``q`` with every joint that can turn more than a full revolution moved by whole turns
        (2π) to the value nearest ``near`` within the limits: the same arm pose, but a goal on the
        far side of a ±2π joint's range would otherwise have to be reached by turning the joint
        (and everything it carries) most of a revolution, e.g. through the floor."""
        turns = np.round((near - q) / (2 * np.pi))
        out = q + 2 * np.pi * turns
        ok = (out >= self.lower - 1e-9) & (out <= self.upper + 1e-9) & ((self.upper - self.lower) > 2 * np.pi + 1e-9)
        return np.where(ok, out, q)

    def search_box(self, qs: np.ndarray, qg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The joint box RRT samples: the limits, narrowed for joints that can turn more than a full
        revolution (e.g. ±2π wrists) to within π beyond the start and goal values, since farther
        angles repeat arm poses already inside that window and only lengthen the path; widened to
        hold the start and the goal where they lie past a limit."""
        lo = np.maximum(self.lower, np.minimum(qs, qg) - np.pi)
        hi = np.minimum(self.upper, np.maximum(qs, qg) + np.pi)
        wide = (self.upper - self.lower) > 2 * np.pi + 1e-9
        lo, hi = np.where(wide, lo, self.lower), np.where(wide, hi, self.upper)
        # a simulated joint can sit a hair past its limit (the drive overshoots): OMPL rejects a
        # start outside the box without a single check, so the box always holds both ends
        return np.minimum(lo, np.minimum(qs, qg)), np.maximum(hi, np.maximum(qs, qg))

    def timed(self, path: PlannedPath, limits: JointLimits) -> Plan:
        """toppra timing of ``path`` (within ``limits``), checked sample by sample; stops at every
        waypoint instead where the smooth path would cut into an obstacle."""
        from robocfg.motion.plan import plan_trajectory

        if len(path.waypoints) == 2:  # one straight segment: the synchronised trapezoid is the time-optimal
            # rest-to-rest timing along a line (toppra's would only tie it, and plan_trajectory then took it)
            return plan_trajectory(path.waypoints, limits, stop_at_waypoints=True)
        s = self.settings
        grid = max(s.min_gridpoints, s.gridpoints_per_segment * (len(path.waypoints) - 1))
        plan = plan_trajectory(path.waypoints, limits, gridpoints=grid)
        if len(path.waypoints) > 2 and plan.path != "linear" and not self.trajectory_valid(plan):
            plan = plan_trajectory(path.waypoints, limits, stop_at_waypoints=True)
            plan.notes.append("the smooth path cut into the margin; stopped at every waypoint instead")
        return plan

    def trajectory_valid(self, plan: Plan) -> bool:
        """True if the trajectory is valid at samples no more than ``resolution`` rad apart."""
        traj = plan.trajectory
        if traj.duration <= 0:
            return True
        q = traj.evaluate(np.linspace(0.0, traj.duration, 2001))[0]  # dense: cheap (vectorised)
        # max-norm travel along the samples; check one sample each time it passes a multiple of
        # the resolution (consecutive checked samples are then at most ``resolution`` apart)
        travel = np.concatenate([[0.0], np.cumsum(np.max(np.abs(np.diff(q, axis=0)), axis=1))])
        ticks = np.floor(travel / self.settings.resolution)
        picked = np.flatnonzero(np.diff(ticks, prepend=-1.0) > 0)
        return all(self.checker.is_valid(q[k]) for k in [*picked, len(q) - 1])
