"""Joint-space trajectory waypoints checked against the arm's joints and URDF limits (no IK).

A waypoint entry of ``trajectory.waypoints`` is ``'home'``, a list of values in arm-joint order
(rad, or m for prismatic joints) or a ``{joint: value}`` map. These forms are fully checkable
without a kinematic model, so ``validate`` reports an unknown joint, a list of the wrong length
or a value outside the limits at the entry's line. Cartesian pose entries need IK and are
resolved when the trajectory is planned (:mod:`robocfg.motion.waypoints`, which uses the same
functions for the joint-space forms).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from robocfg.config.types import Pose
from robocfg.errors import Problem
from robocfg.suggest import did_you_mean

LIMIT_TOL = 1e-9  # rad or m

# problem(loc, message) -> Problem, loc relative to the waypoint list, e.g. (2, "panda_joint4")
ProblemFn = Callable[[tuple, str], Problem]


@dataclass(frozen=True)
class PositionLimits:
    """Position limits of the arm joints, in arm-joint order (rad or m); ``bounded`` False for continuous joints."""

    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    bounded: np.ndarray


def joint_waypoint(i: int, item: str | Sequence[float] | Mapping[str, float], limits: PositionLimits, home: np.ndarray, prev: np.ndarray,
                   problem: ProblemFn, problems: list[Problem]) -> tuple[str, np.ndarray | None]:
    """Joint values of a joint-space entry and its kind ('home', 'map', 'list'); (kind, None) when
    it is invalid (the reason appended to ``problems``). A map's unnamed joints keep ``prev``."""
    names = list(limits.names)
    q: np.ndarray | None = None
    if isinstance(item, str):
        if item == "home":
            q = np.asarray(home, dtype=float).copy()
        else:
            problems.append(problem((i,), f"unknown waypoint name {item!r}{did_you_mean(item, ['home'])} "
                                          "(the only named waypoint is 'home')"))
        return "home", q
    if isinstance(item, Mapping):
        q = np.asarray(prev, dtype=float).copy()
        for jn, v in item.items():
            if jn not in names:
                problems.append(problem((i, jn), f"{jn!r} is not an arm joint{did_you_mean(str(jn), names)} "
                                                 f"(arm joints: {', '.join(names)})"))
                return "map", None
            q[names.index(jn)] = float(v)
        _check_within(i, q, limits, "map", problem, problems, set(item))
        return "map", q
    values = list(item)
    if len(values) != len(names):
        problems.append(problem((i,), f"waypoint {i} has {len(values)} values for {len(names)} arm joints ({', '.join(names)})"))
        return "list", None
    q = np.asarray(values, dtype=float)
    _check_within(i, q, limits, "list", problem, problems)
    return "list", q


def check_within(i: int, q: np.ndarray, limits: PositionLimits, kind: str, problem: ProblemFn,
                 problems: list[Problem]) -> None:
    """Append a problem per joint of ``q`` outside its position limits (± LIMIT_TOL)."""
    _check_within(i, q, limits, kind, problem, problems)


def _check_within(i: int, q: np.ndarray, limits: PositionLimits, kind: str, problem: ProblemFn,
                  problems: list[Problem], only: set | None = None) -> None:
    for k, (jn, v) in enumerate(zip(limits.names, q, strict=True)):
        if not limits.bounded[k] or (only is not None and jn not in only):
            continue
        lo, hi = limits.lower[k], limits.upper[k]
        if v < lo - LIMIT_TOL or v > hi + LIMIT_TOL:
            loc = (i, jn) if kind == "map" else ((i, k) if kind == "list" else (i,))
            problems.append(problem(loc, f"waypoint {i}: {jn} = {v:.4f} is outside its limits [{lo:.4f}, {hi:.4f}]"))


def check_joint_waypoints(items: list, limits: PositionLimits, home: np.ndarray, problem: ProblemFn) -> list[Problem]:
    """Every problem of the joint-space entries of ``items``; Cartesian poses are skipped (they
    need IK), and a map after a pose is checked only on the joints it names."""
    problems: list[Problem] = []
    prev = np.asarray(home, dtype=float)
    for i, item in enumerate(items):
        if isinstance(item, Pose):
            continue
        _, q = joint_waypoint(i, item, limits, home, prev, problem, problems)
        if q is not None:
            prev = q
    return problems
