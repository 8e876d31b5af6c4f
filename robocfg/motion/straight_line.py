"""Straight EE lines in joint space with few IK solves: adaptive subdivision checked by FK.

A straight move goes from FK(q0) to ``T_goal`` (world_T_ee, m) along the segment between their
positions, with the goal's orientation. Instead of an IK solve every few centimetres, the line
is cut into a first guess of ``FIRST_PIECE`` m pieces: IK at the line's end (seeded from q0),
then at the inner cuts in order, each seeded by the joints interpolated between the previous
point's answer (q0 for the first) and the end's (a continuation: the previous answer is nearer the
IK curve than q0, 3.02 -> 2.72 LM iterations a cut on pick-place, docs/benchmarks.md). The joint
path that will actually be played — :func:`robocfg.motion.minjerk_path.joint_path` through the
waypoints, the spline ``MinJerkPath`` times — is then sampled (every ``SAMPLE_STEP`` m of line,
at least ``MIN_SAMPLES`` inside each piece) and its EE checked by FK (pinocchio, one batch):
within ``POSITION_TOLERANCE`` m of the segment and ``ANGLE_TOLERANCE`` rad of the goal's
orientation. A piece that fails, or whose joints move more than ``MAX_JOINT_JUMP`` rad (a branch
flip), gets an IK solve at its middle (seeded by its interpolated joints) and the path is checked
again, down to pieces of ``MIN_PIECE`` m.

The first point: FK(q0)'s orientation may differ from the goal's (a move converges within its
tolerance). As before (every waypoint had the goal's orientation, the first one ``CARTESIAN_STEP``
m along), the orientation may turn from FK(q0)'s to the goal's within the first ``CARTESIAN_STEP``
m: the angle allowed there shrinks linearly from that difference (+ the tolerance) to the tolerance.
When the difference is more than ``ANGLE_TOLERANCE``, the point ``CARTESIAN_STEP`` m along is
solved first, from q0, and is a cut of the first guess (the rest is cut from it); a joint jump of
more than ``MAX_JOINT_JUMP`` there fails the line at once, as the old way did at its first point
(``move(straight=False)`` asks for a line when the direct answer travels far, often after a turn).

A piece still failing at ``MIN_PIECE`` (e.g. the end's IK answer was on another branch than q0's),
or a first-guess pose IK cannot reach (the old way names the first such point along the line),
sends the line to the old way once — IK every ``CARTESIAN_STEP`` m, each seeded from the previous
answer — and that path is checked and subdivided the same way. Failing again: "no continuous IK
along the straight line", with the joint jump (> ``MAX_JOINT_JUMP``) or the EE's distance from the
line (> ``GIVE_UP_DISTANCE`` m) and where; a pose IK cannot reach: "unreachable at X % of the
straight line". Between ``POSITION_TOLERANCE`` and ``GIVE_UP_DISTANCE`` a ``MIN_PIECE`` piece is
kept (what the old way kept, unchecked, at ``CARTESIAN_STEP``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np

from robocfg.motion.joint_travel import joint_travel
from robocfg.motion.minjerk_path import JointSpline, joint_path, joint_path_knots, path_values

if TYPE_CHECKING:
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel

CARTESIAN_STEP = 0.03  # m: the old way's IK spacing, and where the orientation must be the goal's
MAX_JOINT_JUMP = 0.5  # rad between consecutive waypoints of a line (more: a branch flip)
FIRST_PIECE = 0.045  # m: the first guess's longest piece (a 12 cm approach: three)
MIN_PIECE = 0.005  # m: pieces are not cut below this
SAMPLE_STEP = 0.02  # m of line between FK samples (at least MIN_SAMPLES inside each piece)
MIN_SAMPLES = 3
POSITION_TOLERANCE = 5e-5  # m: the played path's EE from the segment
ANGLE_TOLERANCE = math.radians(0.01)  # rad: its orientation from the goal's (past the first CARTESIAN_STEP)
GIVE_UP_DISTANCE = 1e-3  # m: a MIN_PIECE piece further than this from the line breaks the line
_COS_TOLERANCE = math.cos(ANGLE_TOLERANCE)

Solve = Callable[[np.ndarray, np.ndarray], "IKResult"]  # (world_T_ee, seed) -> IK answer
Fail = Callable[[str], Exception]  # reason -> the error to raise
Unreachable = Callable[["IKResult", str], Exception]  # (answer, " at X % of the straight line") -> error
Plan = tuple[list[float], list[np.ndarray]]  # a checked line's waypoints: (line fractions, joints), first to last


class _Line:
    """The segment from FK(q0) to ``T_goal``, IK on it, and the FK check of a joint path."""

    def __init__(self, model: KinematicModel, q0: np.ndarray, T_goal: np.ndarray, ik: Solve):
        # Python floats for the line's few numbers and the per-sample checks of ``errors``: these
        # run once or twice per line, right after hundreds of physics steps, where each small
        # numpy call costs several times its warm cost
        T0 = model.fk(q0, "ee").tolist()
        self.model, self.ik = model, ik
        self.T_goal = np.array(T_goal, dtype=float)
        goal = self.T_goal.tolist()
        self.p0, self.p1 = [r[3] for r in T0[:3]], [r[3] for r in goal[:3]]
        d = [b - a for a, b in zip(self.p0, self.p1, strict=True)]
        self.length = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        self.u = [v / self.length for v in d] if self.length > 0 else [0.0, 0.0, 0.0]
        self.R_goal = [v for r in goal[:3] for v in r[:3]]  # row-major 3x3
        self.turn0 = _angle([v for r in T0[:3] for v in r[:3]], self.R_goal)  # rad to turn in the first CARTESIAN_STEP

    def solve(self, s: float, seed: np.ndarray) -> np.ndarray:
        """IK of the line's pose at fraction ``s`` from ``seed``; raises _Unreachable."""
        T = self.T_goal.copy()
        (x0, y0, z0), (x1, y1, z1) = self.p0, self.p1
        T[:3, 3] = ((1 - s) * x0 + s * x1, (1 - s) * y0 + s * y1, (1 - s) * z0 + s * z1)
        res = self.ik(T, seed)
        if not res.converged:
            raise _Unreachable(res, s)
        return res.q

    def errors(self, path: JointSpline, knots: list[float], S: list[float]) -> tuple[list[float], list[bool]]:
        """Per piece i (between knots i and i+1 of ``path``, line fractions S[i]..S[i+1]): the
        largest distance (m) of the sampled EE from the segment, and whether a sample's
        orientation is further from the goal's than allowed there."""
        samples: list[float] = []
        starts: list[int] = []
        for (a, b), ka, kb in zip(pairwise(S), knots[:-1], knots[1:], strict=True):
            m = max(MIN_SAMPLES, math.ceil(self.length * (b - a) / SAMPLE_STEP))
            starts.append(len(samples))
            samples += [ka + (kb - ka) * j / (m + 1) for j in range(1, m + 1)]
        poses = self.model.fk_pose_rows(path_values(path, samples), "ee")
        (x0, y0, z0), (ux, uy, uz), length, turn0 = self.p0, self.u, self.length, self.turn0
        g0, g1, g2, g3, g4, g5, g6, g7, g8 = self.R_goal
        dist: list[float] = []
        turned: list[bool] = []
        for (r0, r1, r2, px), (r3, r4, r5, py), (r6, r7, r8, pz), _ in poses:
            vx, vy, vz = px - x0, py - y0, pz - z0
            along = vx * ux + vy * uy + vz * uz  # the nearest point of the segment: clipped to [0, length]
            if along < 0.0:
                along = 0.0
            elif along > length:
                along = length
            ox, oy, oz = vx - along * ux, vy - along * uy, vz - along * uz
            dist.append(math.sqrt(ox * ox + oy * oy + oz * oz))
            # cos of the angle to the goal's orientation, (trace(goal_R_ee) - 1) / 2, against the allowed angle's
            cos = (r0 * g0 + r1 * g1 + r2 * g2 + r3 * g3 + r4 * g4 + r5 * g5 + r6 * g6 + r7 * g7 + r8 * g8 - 1.0) / 2.0
            if along < CARTESIAN_STEP:  # the orientation may still be turning from FK(q0)'s
                allowed = ANGLE_TOLERANCE + turn0 * (1.0 - along / CARTESIAN_STEP)
                turned.append(cos < math.cos(min(allowed, math.pi)))
            else:
                turned.append(cos < _COS_TOLERANCE)
        ends = [*starts[1:], len(dist)]
        return ([max(dist[a:b]) for a, b in zip(starts, ends, strict=True)],
                [any(turned[a:b]) for a, b in zip(starts, ends, strict=True)])


def _angle(Ra: list[float], Rb: list[float]) -> float:
    """Angle (rad, in [0, π]) of the rotation taking ``Ra`` to ``Rb`` (row-major 3x3 lists):
    :func:`robocfg.geometry.rotation_angle` in Python floats."""
    c = (sum(a * b for a, b in zip(Ra, Rb, strict=True)) - 1.0) / 2.0
    return math.acos(min(max(c, -1.0), 1.0))


def _linspace(a: float, b: float, num: int) -> list[float]:
    """``np.linspace(a, b, num).tolist()`` (num ≥ 2, a < b) in Python floats: the same
    ``i · step + a`` for each point and ``b`` itself last."""
    step = (b - a) / (num - 1)
    if step == 0.0:  # numpy's other branch (a denormal step): leave it to numpy
        return np.linspace(a, b, num).tolist()
    return [*(i * step + a for i in range(num - 1)), b]


class _Unreachable(Exception):
    """IK did not converge at line fraction ``s``: ``res`` is its best answer."""

    def __init__(self, res: IKResult, s: float):
        super().__init__(s)
        self.res, self.s = res, s


class _Broken(Exception):
    """A ``MIN_PIECE`` piece that cannot be accepted: ``reason`` for the failure message."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def straight_line_path(model: KinematicModel, q0: np.ndarray, T_goal: np.ndarray, ik: Solve,
                       fail: Fail, unreachable: Unreachable) -> tuple[np.ndarray, JointSpline]:
    """Joint waypoints (k, n) from ``q0`` to an IK answer of ``T_goal`` whose played path (the
    second item: :func:`joint_path` of them, for ``MinJerkPath(path=...)``) keeps the EE on the
    straight line (see the module docstring); raises ``fail(reason)`` or ``unreachable``."""
    return straight_line_plan(model, q0, T_goal, ik, fail, unreachable)[:2]


def straight_line_plan(model: KinematicModel, q0: np.ndarray, T_goal: np.ndarray, ik: Solve,
                       fail: Fail, unreachable: Unreachable,
                       earlier: Plan | None = None) -> tuple[np.ndarray, JointSpline, Plan]:
    """:func:`straight_line_path` and the line's plan (its waypoints' line fractions and joints).
    ``earlier``: the plan of a line to the same ``T_goal`` from a start near ``q0`` (e.g. checked
    before the arm moved to that start): its waypoints after the first, behind ``q0``, are kept
    when the path through them passes the FK check as it is (no piece to cut: no IK at all, the
    last waypoint an answer of ``T_goal`` itself); else the line is planned afresh."""
    q0 = np.asarray(q0, dtype=float)
    line = _Line(model, q0, T_goal, ik)
    try:
        if earlier is not None and line.length >= MIN_PIECE:
            kept = _as_checked(line, earlier[0], [q0, *earlier[1][1:]])
            if kept is not None:
                return kept
        try:
            return _first_guess(line, q0, fail)
        except (_Broken, _Unreachable):  # the old way: each point from the last (where it breaks, first)
            n = max(1, math.ceil(line.length / CARTESIAN_STEP - 1e-9))
            S = _linspace(0.0, 1.0, n + 1)
            Q = [q0]
            for s in S[1:]:
                Q.append(line.solve(s, Q[-1]))
            return _refine(line, S, Q)
    except _Unreachable as exc:
        raise unreachable(exc.res, f" at {exc.s:.0%} of the straight line") from None
    except _Broken as exc:
        raise fail(f"no continuous IK along the straight line ({exc.reason})") from None


def _first_guess(line: _Line, q0: np.ndarray, fail: Fail) -> tuple[np.ndarray, JointSpline, Plan]:
    """The line from few IK solves (module docstring), refined; raises _Broken or _Unreachable
    for the old way to try, ``fail`` where the old way would have failed the same."""
    if line.length < MIN_PIECE:  # too short to cut: the goal's answer, checked for a jump
        q1 = line.solve(1.0, q0)
        jump = joint_travel(q0, q1)
        if jump > MAX_JOINT_JUMP:
            raise fail(f"no continuous IK along the straight line (a joint jumps {jump:.2f} rad at 100%)")
        return np.asarray([q0, q1]), joint_path(np.asarray([q0, q1]))[1], ([0.0, 1.0], [q0, q1])
    S, Q = _start(line, q0, fail)
    if S[-1] < 1.0:  # the rest: IK at its end from the last answer, then at the cuts between, in order
        a, qa = S[-1], Q[-1]
        n = max(1, math.ceil(line.length * (1.0 - a) / FIRST_PIECE - 1e-9))
        cuts = _linspace(a, 1.0, n + 1)[1:]
        q1 = line.solve(1.0, qa)
        b, qb = a, qa
        for s in cuts[:-1]:  # a continuation: each seeded between the previous answer and the end's
            qb = line.solve(s, qb + (s - b) / (1.0 - b) * (q1 - qb))
            b = s
            Q.append(qb)
        S += cuts
        Q.append(q1)
    return _refine(line, S, Q)


def _start(line: _Line, q0: np.ndarray, fail: Fail) -> tuple[list[float], list[np.ndarray]]:
    """The first guess's first points (line fractions, joints): q0, and where the orientation
    turns within the first CARTESIAN_STEP, the answer there, from q0 (``fail`` on a jump there)."""
    S, Q = [0.0], [q0]
    if line.turn0 > ANGLE_TOLERANCE:  # the orientation turns within the first CARTESIAN_STEP: that point first, from q0
        s1 = min(1.0, CARTESIAN_STEP / line.length)
        q = line.solve(s1, q0)
        jump = joint_travel(q0, q)
        if jump > MAX_JOINT_JUMP:  # as the old way fails at its first point
            raise fail(f"no continuous IK along the straight line (a joint jumps {jump:.2f} rad at {s1:.0%})")
        S.append(s1)
        Q.append(q)
    return S, Q


def straight_line_end(model: KinematicModel, q0: np.ndarray, T_goal: np.ndarray, ik: Solve,
                      fail: Fail, unreachable: Unreachable) -> np.ndarray:
    """The joints the first guess of :func:`straight_line_path` ends at, without its inner cuts
    and FK check: a joint-space move's candidate goal on q0's branch (its path is played in joint
    space, not along the line). The same answer as the line's last waypoint whenever the first
    guess holds; ``fail`` and ``unreachable`` where its first points fail."""
    q0 = np.asarray(q0, dtype=float)
    line = _Line(model, q0, T_goal, ik)
    try:
        if line.length < MIN_PIECE:
            S, Q = [0.0], [q0]
        else:
            S, Q = _start(line, q0, fail)
        if S[-1] >= 1.0:
            return Q[-1]
        q1 = line.solve(1.0, Q[-1])
    except _Unreachable as exc:
        raise unreachable(exc.res, f" at {exc.s:.0%} of the straight line") from None
    if line.length < MIN_PIECE and (jump := joint_travel(q0, q1)) > MAX_JOINT_JUMP:
        raise fail(f"no continuous IK along the straight line (a joint jumps {jump:.2f} rad at 100%)")
    return q1


def _as_checked(line: _Line, S: list[float], Q: list[np.ndarray]) -> tuple[np.ndarray, JointSpline, Plan] | None:
    """The waypoints ``Q`` (at line fractions ``S``), the path through them and their plan when
    every piece passes :func:`_refine`'s check as it is; None when a piece would be cut or kept
    out of tolerance, or an answer repeats."""
    W = np.asarray(Q)
    W_kept, path, knots = joint_path_knots(W)
    if len(W_kept) != len(W):
        return None
    dist, turned, jumps = _pieces(line, W, path, knots, S)
    if max(dist) > POSITION_TOLERANCE or any(turned) or max(jumps) > MAX_JOINT_JUMP:
        return None
    return W, path, (S, Q)


def _pieces(line: _Line, W: np.ndarray, path: JointSpline, knots: list[float],
            S: list[float]) -> tuple[list[float], list[bool], list[float]]:
    """Per piece of the path through ``W``: :meth:`_Line.errors` and the largest joint step (rad)."""
    dist, turned = line.errors(path, knots, S)
    jumps = [max(abs(b - a) for a, b in zip(qa, qb, strict=True)) for qa, qb in pairwise(W.tolist())]
    return dist, turned, jumps


def _refine(line: _Line, S: list[float], Q: list[np.ndarray]) -> tuple[np.ndarray, JointSpline, Plan]:
    """Cut the failing pieces of the path through ``Q`` (at line fractions ``S``) until every
    piece passes or is ``MIN_PIECE`` short; raises _Broken for a short piece that breaks the line.
    Returns the waypoints, the path through them and their plan ``(S, Q)``."""
    kept: set[tuple[float, float]] = set()  # MIN_PIECE pieces within GIVE_UP_DISTANCE, accepted
    while True:
        W = np.asarray(Q)
        W_kept, path, knots = joint_path_knots(W)
        if len(W_kept) != len(W):  # an answer repeated (the line does not move the joints): nothing to check
            return W, path, (S, Q)
        dist, turned, jumps = _pieces(line, W, path, knots, S)
        new_S, new_Q, cut = [S[0]], [Q[0]], False
        for i in range(len(S) - 1):
            a, b = S[i], S[i + 1]
            bad = dist[i] > POSITION_TOLERANCE or turned[i] or jumps[i] > MAX_JOINT_JUMP
            if bad and (a, b) not in kept:
                if line.length * (b - a) >= 2 * MIN_PIECE:
                    m = 0.5 * (a + b)
                    new_S.append(m)
                    new_Q.append(line.solve(m, 0.5 * (Q[i] + Q[i + 1])))
                    cut = True
                elif jumps[i] > MAX_JOINT_JUMP:
                    raise _Broken(f"a joint jumps {jumps[i]:.2f} rad at {b:.0%}")
                elif dist[i] > GIVE_UP_DISTANCE:
                    raise _Broken(f"the EE leaves the line by {dist[i] * 1000:.1f} mm at {b:.0%}")
                else:
                    kept.add((a, b))
            new_S.append(b)
            new_Q.append(Q[i + 1])
        if not cut:
            return W, path, (S, Q)
        S, Q = new_S, new_Q
