"""Plan a timed joint trajectory through waypoints: the one entry point the runner uses.

* ``stop_at_waypoints=False`` (default): a C² spline through the waypoints (PCHIP if the spline
  would leave the joint limits), timed by toppra — time-optimal along that path, passing through
  every waypoint without stopping. The stop-at-every-waypoint trapezoids are also computed (they
  cost < 1 ms) and used instead when they are faster — e.g. when every joint reverses at the
  waypoints (home → reach-out → home), or when the spline makes a long detour between waypoints
  far apart — so the result is never slower than stopping (``Plan.notes`` says so).
* ``stop_at_waypoints=True``: straight segments, a synchronised trapezoid each, at rest at every
  waypoint (Isaac Sim's semantics).
* a jerk limit: ruckig segments through the waypoints (see :mod:`robocfg.motion.jerk`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from robocfg.motion.limits import JointLimits
from robocfg.motion.path import DUPLICATE_TOL, drop_repeats, smooth_path
from robocfg.motion.trajectory import Trajectory


class Hold(Trajectory):
    """Stay at ``q`` (duration 0)."""

    def __init__(self, q: np.ndarray):
        self.q, self.duration = np.asarray(q, float), 0.0

    def _eval(self, t):
        z = np.zeros((len(t), len(self.q)))
        return self.q + z, z.copy(), z.copy()


@dataclass
class Plan:
    """A planned trajectory and how it was made."""

    trajectory: Trajectory
    waypoints: np.ndarray  # (k, n) distinct waypoints actually used
    waypoint_indices: list[int]  # their indices in the input
    waypoint_times: list[float]  # s, when each is passed
    method: str  # "toppra", "trapezoid", "ruckig" or "hold"
    path: str  # "spline", "pchip", "linear" or "none"
    gridpoints: int | None
    fit_factor: float  # uniform slow-down applied after toppra (1.0 = none)
    planning_time: float  # s, wall clock
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # informational (e.g. why a method was chosen)

    @property
    def duration(self) -> float:
        return float(self.trajectory.duration)


def load_libraries(jerk: bool = False) -> None:
    """Import toppra/scipy (and ruckig) and the timing modules now, so ``planning_time`` measures
    planning, not the one-off imports (toppra pulls in scipy and matplotlib: 1–3 s cold)."""
    import scipy.interpolate  # noqa: F401
    import toppra.algorithm
    import toppra.constraint  # noqa: F401

    import robocfg.motion.timing
    import robocfg.motion.trapezoid

    if jerk:
        import ruckig  # noqa: F401

        import robocfg.motion.jerk  # noqa: F401


def plan_trajectory(waypoints, limits: JointLimits, stop_at_waypoints: bool = False,
                    gridpoints: int | None = None) -> Plan:
    """Time a trajectory through ``waypoints`` (k, n) in joint order of ``limits``, rest to rest.

    Consecutive repeated waypoints are dropped with a warning. Waypoints are assumed to be within
    the position limits (the caller checks them, with file locations). ``planning_time`` excludes
    the first import of the libraries.
    """
    load_libraries(limits.jerk is not None)
    t0 = time.perf_counter()
    W = np.asarray(waypoints, dtype=float)
    if W.ndim != 2 or W.shape[1] != limits.dof or len(W) == 0:
        raise ValueError(f"waypoints must have shape (k, {limits.dof}), got {W.shape}")
    d = drop_repeats(W)
    warnings = [f"waypoint {i} repeats waypoint {i - 1} (within {DUPLICATE_TOL:g} rad); dropped" for i in d.dropped]
    Wd = d.waypoints
    if len(Wd) == 1:
        warnings.append("only one distinct waypoint: nothing to move")
        return Plan(Hold(Wd[0]), Wd, d.kept, [0.0], "hold", "none", None, 1.0,
                    time.perf_counter() - t0, warnings)
    from robocfg.motion.trapezoid import stop_at_waypoints as trapezoids

    if stop_at_waypoints and limits.jerk is None:
        traj = trapezoids(Wd, limits)
        return Plan(traj, Wd, d.kept, [float(x) for x in traj.starts], "trapezoid", "linear", None, 1.0,
                    time.perf_counter() - t0, warnings)
    if stop_at_waypoints:  # and a jerk limit: rest-to-rest ruckig segments
        from robocfg.motion.jerk import jerk_limited

        jt = jerk_limited(Wd, np.zeros_like(Wd), limits)
        return Plan(jt, Wd, d.kept, [float(x) for x in jt.starts], "ruckig", "none", None, 1.0,
                    time.perf_counter() - t0, warnings)
    from robocfg.motion.timing import time_optimal

    notes: list[str] = []
    path = smooth_path(Wd, limits.lower, limits.upper, limits.bounded())
    if path.kind == "pchip":
        notes.append("the spline through the waypoints would leave the joint limits; used a shape-preserving (PCHIP) path")
    tr = time_optimal(path, limits, gridpoints)
    times = [float(x) for x in tr.f.time_at(path.knots) * tr.k]
    if limits.jerk is not None:  # pass each waypoint at toppra's velocity, jerk-limited by ruckig
        from robocfg.motion.jerk import jerk_limited

        jt = jerk_limited(Wd, tr.evaluate(np.asarray(times))[1], limits)
        return Plan(jt, Wd, d.kept, [float(x) for x in jt.starts], "ruckig", "none", None, 1.0,
                    time.perf_counter() - t0, warnings, notes)
    stop = trapezoids(Wd, limits)
    if stop.duration < tr.duration:  # e.g. every joint reverses at the waypoints, or a long detour
        notes.append(f"stopping at every waypoint is faster here ({stop.duration:.3f} s) than the "
                     f"smooth path ({tr.duration:.3f} s); used it")
        return Plan(stop, Wd, d.kept, [float(x) for x in stop.starts], "trapezoid", "linear", None, 1.0,
                    time.perf_counter() - t0, warnings, notes)
    return Plan(tr, Wd, d.kept, times, "toppra", path.kind, len(tr.f.ss), tr.k,
                time.perf_counter() - t0, warnings, notes)
