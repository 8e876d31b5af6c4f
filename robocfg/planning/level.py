"""Carry a held object as it was picked up: the hand's orientation kept along a planned path.

A joint path from RRT-Connect passes through random arm configurations, so the hand turns on the
way (measured on the obstacle task: tilts up to 21° and turns up to 8° about the vertical going
over the wall, and back). The held box lags a fraction of a degree behind the pads as the hand
turns, and PyBullet's finger–box contact manifolds then gather 3–7 points between the two pads
instead of 2, which they keep until the release: physics steps cost about twice as much for the rest of
the carry and the lowering (transport 209 against 133 µs a step, lower 246 against 103, against
the trajectory mode without the wall, 10 episodes). Nothing made the hand turn but the random
samples.

:func:`level_path` re-solves each interior waypoint of a collision-free path with the hand at the
orientation of the path's goal, turned about the held object's centre (``pivot``), which stays
where the path had it, clear of the scene; where a straight joint segment between two waypoints
is not valid, or turns the hand by more than ``max_tilt`` from that orientation between them, it
goes through a midpoint solved the same way (halving, ``max_depth`` times at most). A waypoint
that cannot be reached so from the one before is tried raised by ``rises`` (over the edge the
turn had cleared: on the obstacle task 4 of 30 carries needed it). If no height works for a
waypoint, or the last segment cannot be mended, the path is returned as it was:
the result is always collision-free for the checker at ``step``. Joint values in rad (arm order),
angles in rad, poses world_T_ee (4×4, m).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robocfg.planning.checker import CollisionChecker

Solve = Callable[[np.ndarray, np.ndarray], "np.ndarray | None"]  # (world_T_ee target, seed q) -> q, None: no answer
Fk = Callable[[np.ndarray], np.ndarray]  # q -> world_T_ee (4×4)


@dataclass(frozen=True)
class LevelSettings:
    max_tilt: float = np.radians(6.0)  # rad: most the hand may turn from the goal's orientation between waypoints
    samples: int = 8  # points per segment at which the hand's turn is measured (ends excluded)
    max_depth: int = 3  # halvings of one segment at most (≤ 2³ − 1 inserted waypoints per segment)
    rises: tuple[float, ...] = (0.0, 0.03, 0.06)  # m: heights a levelled waypoint is tried at, in turn


def turn(R: np.ndarray, R_goal: np.ndarray) -> float:
    """Angle (rad) of the rotation between ``R`` and ``R_goal``."""
    return float(np.arccos(np.clip((np.trace(R.T @ R_goal) - 1.0) / 2.0, -1.0, 1.0)))


def level_path(path: np.ndarray, checker: CollisionChecker, fk: Fk, solve: Solve, step: float,
               pivot: np.ndarray | None = None, settings: LevelSettings = LevelSettings()) -> np.ndarray:
    """``path`` (k, n) with the hand held at the orientation of its last waypoint (module
    docstring), or ``path`` itself where that cannot be done or the hand starts turned from that
    orientation by more than ``max_tilt``; ``step`` (rad): the checker's segment resolution;
    ``pivot`` (m, EE frame, default its origin): the point a waypoint's hand is turned about (the
    held object's centre: it stays where the path had it, clear of the scene)."""
    P = np.asarray(path, float)
    R_goal = fk(P[-1])[:3, :3].copy()
    if len(P) < 3 or turn(fk(P[0])[:3, :3], R_goal) > settings.max_tilt:
        return P
    pivot = np.zeros(3) if pivot is None else np.asarray(pivot, float)

    def level(q: np.ndarray, rise: float = 0.0) -> np.ndarray | None:
        T = fk(q)
        if rise == 0.0 and turn(T[:3, :3], R_goal) <= 1e-9:
            return q
        T_new = T.copy()
        T_new[:3, :3] = R_goal
        T_new[:3, 3] = T[:3, :3] @ pivot + T[:3, 3] - R_goal @ pivot + [0.0, 0.0, rise]
        q_new = solve(T_new, q)
        return q_new if q_new is not None and checker.is_valid(q_new) else None

    fractions = np.arange(1, settings.samples + 1) / (settings.samples + 1)

    def connect(qa: np.ndarray, qb: np.ndarray, depth: int) -> list[np.ndarray] | None:
        """Waypoints after ``qa`` up to ``qb`` (included): the straight segment if it is valid and
        keeps the hand within ``max_tilt``, else through a levelled midpoint; None: not found."""
        valid = checker.segment_valid(qa, qb, step)
        if valid and max(turn(fk(qa + f * (qb - qa))[:3, :3], R_goal) for f in fractions) <= settings.max_tilt:
            return [qb]
        mid = level(0.5 * (qa + qb)) if depth < settings.max_depth else None
        if mid is None:
            return [qb] if valid else None
        first, second = connect(qa, mid, depth + 1), connect(mid, qb, depth + 1)
        if first is None or second is None:
            return [qb] if valid else None
        return [*first, *second]

    out = [P[0]]
    for q in P[1:-1]:  # each waypoint levelled where it was, else raised (over what the turn avoided)
        part = None
        for rise in settings.rises:
            target = level(q, rise)
            part = None if target is None else connect(out[-1], target, 0)
            if part is not None:
                break
        if part is None:
            return P
        out += part
    last = connect(out[-1], P[-1], 0)
    return P if last is None else np.asarray([*out, *last])
