"""Joint-space RRT-Connect through OMPL (the ``ompl`` wheel), against a :class:`CollisionChecker`.

OMPL samples the arm's joint box (position limits) and connects two trees grown from the start
and the goal; every new state and every edge (at ``resolution`` rad, middle-first) must pass the
checker. The search stops at the first solution or after ``max_checks`` collision checks;
``budget`` seconds of wall clock end it only when no check count is set (``max_checks`` 0).

Reproducibility: OMPL draws every random number from generators seeded from one process-wide
sequence. Before each query that sequence is rewound to its first seed (OMPL logs an error for
this, silenced here), so a query's answer depends only on its start, goal, scene and settings, not
on what was planned before it. The check count, never the wall clock, ends a hopeless search, so
the answer does not depend on the machine's load either (a wall-clock "safety net" would, on a
machine loaded enough to reach it).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from robocfg.planning.checker import CollisionChecker

OMPL_SEED = 1  # first seed of OMPL's process-wide seed sequence (OMPL rejects 0)


@dataclass(frozen=True)
class RRTSettings:
    resolution: float = 0.02  # rad: edges are checked at this spacing (max over joints)
    range: float = 0.0  # rad: longest tree extension (0: OMPL's default, 20 % of the box diagonal)
    max_checks: int = 40_000  # collision checks per query (deterministic stop)
    budget: float = 2.0  # s of wall clock per query, consulted only without max_checks


@dataclass(frozen=True)
class RRTResult:
    """Outcome of one query: the raw tree path (k, n) or None, collision checks used, wall time (s)."""

    path: np.ndarray | None
    checks: int
    seconds: float
    stopped_by: str  # "solved" | "checks" | "budget"


def _rewind_ompl_rng() -> None:
    """Make the next OMPL random generators start from the same seeds as the first query's."""
    from ompl import util as ou

    ou.setLogLevel(ou.LOG_NONE)  # the rewind logs "changing seed now will not ..." as an error
    ou.RNG.setSeed(OMPL_SEED)


def rrt_connect(checker: CollisionChecker, q_start: np.ndarray, q_goal: np.ndarray,
                lower: np.ndarray, upper: np.ndarray, settings: RRTSettings = RRTSettings()) -> RRTResult:
    """A collision-free joint path from ``q_start`` to ``q_goal`` (both must be valid), inside the
    joint box [``lower``, ``upper``] (rad)."""
    from ompl import base as ob
    from ompl import geometric as og

    _rewind_ompl_rng()
    n = len(q_start)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i in range(n):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    # the longest joint-space step between checked states: resolution along the diagonal
    space.setLongestValidSegmentFraction(min(1.0, settings.resolution / space.getMaximumExtent()))
    ss = og.SimpleSetup(space)
    checks0 = checker.checks
    buf = np.empty(n)

    def valid(state) -> bool:
        for i in range(n):
            buf[i] = state[i]
        return checker.is_valid(buf)

    ss.setStateValidityChecker(valid)
    start, goal = space.allocState(), space.allocState()
    for i in range(n):
        start[i], goal[i] = float(q_start[i]), float(q_goal[i])
    ss.setStartAndGoalStates(start, goal)
    planner = og.RRTConnect(ss.getSpaceInformation())
    if settings.range > 0:
        planner.setRange(settings.range)
    ss.setPlanner(planner)
    t0 = time.perf_counter()
    deadline = t0 + settings.budget

    def stop() -> bool:
        if settings.max_checks > 0:  # the count alone: the same answer however loaded the machine
            return checker.checks - checks0 >= settings.max_checks
        return time.perf_counter() > deadline

    solved = ss.solve(ob.PlannerTerminationCondition(stop))
    seconds = time.perf_counter() - t0
    checks = checker.checks - checks0
    exact = bool(solved) and str(solved) == "Exact solution"
    path = None
    if exact:
        states = ss.getSolutionPath().getStates()
        path = np.array([[s[i] for i in range(n)] for s in states])
    stopped = "solved" if exact else ("checks" if checks >= settings.max_checks else "budget")
    return RRTResult(path, checks, seconds, stopped)
