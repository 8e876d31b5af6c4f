"""Shorten a collision-free joint path by replacing parts of it with straight, still-valid segments.

RRT paths zig-zag (each tree edge heads for a random sample). Two passes, both keeping every
segment valid for the checker at ``step`` rad:

1. *vertex shortcut*: from each kept vertex jump to the farthest later vertex reachable in a
   straight line (deterministic, O(k²) segment checks for k vertices; k is small after RRT-Connect);
2. *random shortcuts*: ``attempts`` times, pick two points anywhere along the path (by arc length,
   from the given generator) and join them if the segment between them is valid (what OMPL's
   ``PathSimplifier::shortcutPath`` does, here with a seeded generator so the result is reproducible).

Joint values in rad; lengths are Euclidean joint-space arc lengths (rad).
"""

from __future__ import annotations

import numpy as np

from robocfg.planning.checker import CollisionChecker


def path_length(path: np.ndarray) -> float:
    """Euclidean joint-space length (rad) of a polyline (k, n)."""
    P = np.asarray(path, float)
    return float(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=1))) if len(P) > 1 else 0.0


def vertex_shortcut(path: np.ndarray, checker: CollisionChecker, step: float) -> np.ndarray:
    """Greedy: from each kept vertex, the farthest later vertex joined by a valid segment."""
    P = np.asarray(path, float)
    out, i = [P[0]], 0
    while i < len(P) - 1:
        j = len(P) - 1
        while j > i + 1 and not checker.segment_valid(P[i], P[j], step):
            j -= 1
        out.append(P[j])
        i = j
    return np.asarray(out)


def _point_at(P: np.ndarray, cum: np.ndarray, s: float) -> tuple[int, np.ndarray]:
    """(index of the segment containing arc length ``s``, the point there)."""
    k = int(np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(P) - 2))
    seg = cum[k + 1] - cum[k]
    f = 0.0 if seg <= 0 else (s - cum[k]) / seg
    return k, P[k] + f * (P[k + 1] - P[k])


def random_shortcuts(path: np.ndarray, checker: CollisionChecker, step: float, rng: np.random.Generator,
                     attempts: int = 20) -> np.ndarray:
    """Join ``attempts`` random pairs of path points by straight segments where those are valid."""
    P = np.asarray(path, float)
    for _ in range(attempts):
        if len(P) < 3:
            break
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
        s1, s2 = np.sort(rng.uniform(0.0, cum[-1], 2))
        k1, p1 = _point_at(P, cum, s1)
        k2, p2 = _point_at(P, cum, s2)
        if k1 == k2:  # both on one straight segment already
            continue
        if checker.segment_valid(p1, p2, step):
            P = np.vstack([P[: k1 + 1], p1, p2, P[k2 + 1:]])
            P = _drop_duplicates(P)
    return P


def _drop_duplicates(P: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    keep = np.concatenate([[True], np.linalg.norm(np.diff(P, axis=0), axis=1) > tol])
    return P[keep]


def shortcut(path: np.ndarray, checker: CollisionChecker, step: float, rng: np.random.Generator,
             attempts: int = 20) -> np.ndarray:
    """Both passes, then the vertex pass again (random shortcuts add vertices it can remove)."""
    P = vertex_shortcut(path, checker, step)
    P = random_shortcuts(P, checker, step, rng, attempts)
    return vertex_shortcut(P, checker, step)
