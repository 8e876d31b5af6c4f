"""Local-minimum escape rule for reactive target following (pure numpy).

A QP controller with collision constraints can stall head-on against an obstacle: the target pull
and the constraint cancel. The rule watches the tracking error and the TCP; when neither the error
has shrunk nor the TCP has moved by ``min_progress`` over ``stall_time`` while a robot–environment
pair is at the safety margin, it
places a temporary via point on the obstacle's tangent plane (preferring "over", i.e. world +z),
tracks it until it is reached or ``max_time`` passes, then returns to the real target. Repeated
stalls lengthen the step and try the next direction; after ``max_attempts`` the rule gives up
until the target is reached or moves by ``target_moved`` (a blocked target is held, not thrashed
at). A target that lies within ``margin + target_clearance`` of the environment (inside or
against an obstacle or the table) cannot be reached by any detour: no escape is tried.
Units: m, s; frames: world.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EscapeSettings:
    enabled: bool = True
    stall_time: float = 0.3  # s without progress before escaping
    min_progress: float = 0.004  # m of error decrease that counts as progress over stall_time
    min_error: float = 0.015  # m: a smaller error is "reached", never a stall
    near: float = 0.015  # m above the safety margin: a pair this close counts as blocking
    step: float = 0.12  # m: via point distance along the tangent plane
    up_weight: float = 0.7  # "over-and-around" candidates: weight of +z vs. sideways
    max_time: float = 1.5  # s a via point is kept at most
    reach: float = 0.02  # m: via point counts as reached
    max_attempts: int = 3  # escapes per blocked episode (reset once the target is reached or moves on)
    target_clearance: float = 0.03  # m: a target within margin + this of the environment is blocked, not a local minimum
    target_moved: float = 0.05  # m the target must move to start a new episode


@dataclass(frozen=True)
class Blocking:
    """The closest robot–environment pair: distance (m) and unit normal from the obstacle to the robot."""

    distance: float
    normal: np.ndarray


def _unit(v: np.ndarray) -> np.ndarray | None:
    n = float(np.linalg.norm(v))
    return v / n if n > 1e-9 else None


class EscapeRule:
    """Stall detector + tangent-plane via points. Call :meth:`update` once per control step."""

    def __init__(self, settings: EscapeSettings, margin: float):
        self.s, self.margin = settings, margin
        self.history: deque[tuple[float, float, np.ndarray]] = deque()
        self.via: np.ndarray | None = None
        self.via_since = 0.0
        self.attempts = 0
        self.count = 0  # escapes started during the run
        self.episode_target: np.ndarray | None = None
        # distance (m) from a world point to the environment; set by the controller
        self.clearance_fn: Callable[[np.ndarray], float] | None = None
        self.blocked_target = False  # the last stall was at a target the gripper cannot reach

    @property
    def active(self) -> bool:
        return self.via is not None

    def reset(self) -> None:
        self.history.clear()
        self.via, self.attempts = None, 0

    def update(self, t: float, tcp: np.ndarray, target: np.ndarray, blocking: list[Blocking]) -> np.ndarray:
        """The position to track now: ``target``, or a via point while escaping.

        ``blocking``: the robot–environment pairs within reach of the QP (any order)."""
        if not self.s.enabled:
            return target
        tcp, target = np.asarray(tcp, float), np.asarray(target, float)
        if self.via is not None:
            if np.linalg.norm(tcp - self.via) < self.s.reach or t - self.via_since > self.s.max_time:
                self.via = None
                self.history.clear()
            else:
                return self.via
        err = float(np.linalg.norm(target - tcp))
        if self.episode_target is not None and np.linalg.norm(target - self.episode_target) > self.s.target_moved:
            self.attempts, self.episode_target, self.blocked_target = 0, None, False  # a new situation
        self.history.append((t, err, tcp))
        active = [b for b in blocking if b.distance < self.margin + self.s.near]
        while self.history and t - self.history[0][0] > self.s.stall_time:
            _t0, e0, p0 = self.history.popleft()
            stuck = e0 - err < self.s.min_progress and float(np.linalg.norm(tcp - p0)) < self.s.min_progress
            if stuck and err > self.s.min_error and active and self.attempts < self.s.max_attempts:
                self.episode_target = target.copy()
                if self.clearance_fn is not None and self.clearance_fn(target) < self.margin + self.s.target_clearance:
                    self.attempts, self.blocked_target = self.s.max_attempts, True  # no detour reaches it: hold
                    break
                self._start(t, tcp, target, active)
                return self.via  # type: ignore[return-value]
        if err < self.s.min_error:
            self.attempts, self.episode_target, self.blocked_target = 0, None, False
        return target

    def _start(self, t: float, tcp: np.ndarray, target: np.ndarray, active: list[Blocking]) -> None:
        """Pick a via direction: slide along the tangent plane of the pair that most opposes the
        motion, go over, or go around (either side), in that order of preference, skipping
        directions that would push into another active pair; repeats rotate through the list."""
        d = target - tcp
        normals = [u for u in (_unit(np.asarray(b.normal, float)) for b in active) if u is not None]
        if not normals:
            normals = [np.array([0.0, 0.0, 1.0])]
        n = min(normals, key=lambda u: float(u @ d))  # the most opposing pair
        z = np.array([0.0, 0.0, 1.0])
        tangent = d - float(d @ n) * n
        side = _unit(np.cross(n, z))
        if side is None:  # n is vertical: sideways = horizontal, perpendicular to the motion
            side = _unit(np.cross(z, d))
            if side is None:
                side = np.array([0.0, 1.0, 0.0])
        candidates: list[np.ndarray | None] = []
        if np.linalg.norm(tangent) > 0.3 * np.linalg.norm(d):
            candidates.append(_unit(tangent))
        candidates += [_unit(z - float(z @ n) * n), _unit(self.s.up_weight * z + (1 - self.s.up_weight) * side),
                       _unit(self.s.up_weight * z - (1 - self.s.up_weight) * side), side, -side]
        usable = [c for c in candidates if c is not None]
        feasible = [c for c in usable if all(float(c @ m) >= -0.2 for m in normals)] or usable
        direction = feasible[self.attempts % len(feasible)]
        scale = 1.0 + 0.5 * self.attempts
        self.via = tcp + self.s.step * scale * direction + self.s.near * n
        self.via_since = t
        self.attempts += 1
        self.count += 1
        self.history.clear()
