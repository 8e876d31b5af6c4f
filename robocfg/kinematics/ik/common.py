"""Helpers shared by the IK backends: target checks, residuals, limits and wrapping."""

from __future__ import annotations

import math
from collections.abc import Callable
from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from robocfg.errors import RobocfgError
from robocfg.kinematics.ik.result import IKResult

if TYPE_CHECKING:
    from robocfg.kinematics.model import KinematicModel

TWO_PI = 2 * math.pi
LIMIT_TOL = 1e-6  # rad or m: "at a limit"
_F64 = np.dtype(float)  # the float64 dtype (one object: a dtype check by identity)


def check_target(target: np.ndarray) -> np.ndarray:
    """A finite 4x4 homogeneous transform with a proper rotation block, as float64 (a copy).

    Written with Python scalars: it runs once per IK query and numpy's per-call overhead would
    dominate on a 4x4 matrix.
    """
    T = target.copy() if type(target) is np.ndarray and target.dtype is _F64 else np.array(target, dtype=float)
    if T.shape != (4, 4):
        raise RobocfgError(f"IK target must be a 4x4 homogeneous matrix, got shape {T.shape}")
    (a, b, c, x), (d, e, f, y), (g, h, i, z), (m0, m1, m2, m3) = T.tolist()
    if not math.isfinite(a + b + c + x + d + e + f + y + g + h + i + z + m0 + m1 + m2 + m3):
        raise RobocfgError("IK target contains NaN or infinite values")
    rotation = (a, b, c, d, e, f, g, h, i)
    if rotation == _last_rotation[0]:  # a straight line's targets share the goal's rotation: checked once
        return T
    worst = max(abs(a * a + b * b + c * c - 1.0), abs(d * d + e * e + f * f - 1.0),
                abs(g * g + h * h + i * i - 1.0), abs(a * d + b * e + c * f),
                abs(a * g + b * h + c * i), abs(d * g + e * h + f * i))
    det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    if worst > 1e-6 or abs(det - 1.0) > 1e-6:
        raise RobocfgError("IK target rotation is not a rotation matrix (orthonormal, det +1)")
    _last_rotation[0] = rotation
    return T


_last_rotation: list[tuple[float, ...]] = [()]  # the rotation block (row-major) check_target last accepted


def check_seed(model: KinematicModel, seed_q: np.ndarray) -> np.ndarray:
    """The seed as a float array (a copy) brought into the limits (wrapped or clamped).

    A seed already within the limits (the usual case: a measured or previous answer) is checked
    with Python scalars and returned as copied; ``into_limits`` would leave its values as they are.
    """
    if type(seed_q) is np.ndarray and seed_q.dtype is _F64 and seed_q.ndim == 1:
        q = seed_q.copy()  # what np.array(..., dtype=float) gives, without its type discovery
    else:
        q = np.array(seed_q, dtype=float).reshape(-1)
    values = q.tolist()
    if len(values) != model.nq:
        raise RobocfgError(f"seed_q has {q.shape[0]} values; the arm has {model.nq} joints")
    lo, hi = model.limit_lists
    for a, v, b in zip(lo, values, hi):  # noqa: B905 - nq values each
        if not a <= v <= b:  # False for NaN
            break
    else:
        return q
    if not np.isfinite(q).all():
        raise RobocfgError("seed_q contains NaN or infinite values")
    return into_limits(model, q)


def prepare(model: KinematicModel, target: np.ndarray, seed_q: np.ndarray, frame: str):
    """The checked inputs every backend starts from: (T target 4x4, q0 seed, frame id, target SE3)."""
    T = check_target(target)
    q0 = check_seed(model, seed_q)
    return T, q0, model.frame_id(frame), pin.SE3(T)  # the homogeneous matrix's blocks, as from slices


def into_limits(model: KinematicModel, q: np.ndarray) -> np.ndarray:
    """``q`` within the limits: wrapped joints (≥ 2π wide) outside their range are shifted by
    multiples of 2π (values already inside are kept), the others are clamped."""
    q = q.copy()
    if model.any_wrap:
        w, lo, hi = model.wrap, model.lower, model.upper
        q = np.where(w & (q > hi), q - TWO_PI * np.ceil((q - hi) / TWO_PI), q)
        q = np.where(w & (q < lo), q + TWO_PI * np.ceil((lo - q) / TWO_PI), q)
    return np.minimum(np.maximum(q, model.lower), model.upper)


def nearest_equivalent(model: KinematicModel, q: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """``q`` with each wrapped joint moved by a multiple of 2π to the value within its limits
    nearest to ``ref`` (the seed): the same pose, the least joint travel."""
    if not model.any_wrap:
        return q
    cand = q + TWO_PI * np.round((ref - q) / TWO_PI)
    cand = np.where(cand > model.upper, cand - TWO_PI, cand)
    cand = np.where(cand < model.lower, cand + TWO_PI, cand)
    ok = model.wrap & (cand >= model.lower) & (cand <= model.upper)
    return np.where(ok, cand, q)


def residuals(T: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """(position error m, rotation angle rad) between two 4x4 poses."""
    dp = float(np.linalg.norm(T[:3, 3] - target[:3, 3]))
    w = pin.log3(target[:3, :3].T @ T[:3, :3])
    return dp, float(np.linalg.norm(w))


def joints_at_limit(model: KinematicModel, q: np.ndarray) -> list[str]:
    """Names of the (non-wrapped) joints within LIMIT_TOL of a limit."""
    names, index, lower, upper = model.bounded
    values = q.tolist()
    if len(index) != len(values):
        values = [values[k] for k in index]
    out = []
    for n, v, lo, hi in zip(names, values, lower, upper):  # noqa: B905 - one value per bounded joint
        if v - lo <= LIMIT_TOL or hi - v <= LIMIT_TOL:
            out.append(n)
    return out


Descend = Callable[[np.ndarray, float, "int | None"], tuple[bool, int, float, np.ndarray]]


def search(km: KinematicModel, descend: Descend, q0: np.ndarray, deadline: float,
           rng: np.random.Generator | None, clock: Callable[[], float] | None = None,
           max_total_iter: int | None = None,
           restart: Callable[[np.random.Generator], np.ndarray] | None = None,
           whole_first: bool = False) -> tuple[np.ndarray, int, int]:
    """Run ``descend(q, deadline, cap) -> (converged, iterations, score, q)`` from ``q0``, then from
    restart configurations (``restart(rng)``; default: uniform within the limits), until one
    converges, the deadline passes or ``max_total_iter`` iterations have been spent (``cap``: the
    iterations left, None: no cap). ``rng`` None: ``default_rng(0)``.

    ``deadline`` is on ``clock`` (default ``time.perf_counter``). ``whole_first``: the first
    descent, from ``q0``, runs to its own end (convergence, a stall or its iteration cap) and the
    deadline bounds the restarts only, so a target near the seed is found however loaded the
    machine is (a process paused for longer than the budget mid-descent returns unconverged
    otherwise); for solvers whose descent is short next to any budget (LM: 20 iterations). With
    ``max_total_iter`` set the deadline is not consulted at all (``descend`` gets ``inf``): the
    iteration count alone ends the search, so the answer is the same on a loaded machine as on a
    quiet one.
    Returns (best q by score, total iterations, restarts).
    """
    clock = clock or perf_counter
    if max_total_iter is not None:
        deadline = math.inf
    best_s, best_q = math.inf, q0
    iters = restarts = 0
    q = q0
    while True:
        cap = None if max_total_iter is None else max_total_iter - iters
        ok, it, s, q_end = descend(q, math.inf if whole_first and not restarts else deadline, cap)
        iters += it
        if s < best_s:
            best_s, best_q = s, q_end
        if ok or clock() >= deadline or (max_total_iter is not None and iters >= max_total_iter):
            return best_q, iters, restarts
        restarts += 1
        if rng is None:
            rng = np.random.default_rng(0)
        q = rng.uniform(km.lower, km.upper) if restart is None else restart(rng)


class Descent:
    """The bookkeeping of one descent, step by step: the best configuration so far by error
    ``s = position error + rotation error`` (m + rad), convergence (both errors within
    ``tol_pos``/``tol_rot``), and stalls (``stall_n`` steps in a row without ``s`` dropping below
    ``stall_ratio`` times its last reference value)."""

    def __init__(self, q0: np.ndarray, tol_pos: float, tol_rot: float, stall_ratio: float, stall_n: int):
        self.tol_pos, self.tol_rot, self.stall_ratio, self.stall_n = tol_pos, tol_rot, stall_ratio, stall_n
        self.best_s, self.best_q, self.ref_s, self.stall = math.inf, q0, math.inf, 0

    def step(self, q: np.ndarray, pe: float, re: float) -> bool | None:
        """Record the configuration ``q`` with errors ``pe`` (m) and ``re`` (rad): True when it
        converged, False when the descent has stalled, None to go on."""
        s = pe + re
        if s < self.best_s:
            self.best_s, self.best_q = s, q
        if pe <= self.tol_pos and re <= self.tol_rot:
            return True
        if s < self.ref_s * self.stall_ratio:
            self.ref_s, self.stall = s, 0
        else:
            self.stall += 1
            if self.stall >= self.stall_n:
                return False
        return None


def finish(km: KinematicModel, backend: str, q: np.ndarray, Mt: pin.SE3, fid: int, position_only: bool,
           tol_pos: float, tol_rot: float, t0: float, iters: int, restarts: int,
           squared: tuple[float, float] | None = None) -> IKResult:
    """The IKResult for ``q``: residuals by FK (m, rad), convergence against the tolerances.
    ``squared``: (position², rotation²) already measured at ``q`` itself — the same FK and
    logarithm (``log6``'s angular part is ``log3``), so the same floats — sparing a second FK."""
    if squared is None:
        pin.forwardKinematics(km.model, km.data, q)
        d = pin.updateFramePlacement(km.model, km.data, fid).actInv(Mt)
        pe = math.sqrt(d.translation.dot(d.translation))
        w = pin.log3(d.rotation)
        re = 0.0 if position_only else math.sqrt(w.dot(w))
    else:
        pe, re = math.sqrt(squared[0]), 0.0 if position_only else math.sqrt(squared[1])
    return IKResult(q=q, converged=bool(pe <= tol_pos and re <= tol_rot), pos_err=pe, rot_err=re,
                    iterations=iters, time_s=perf_counter() - t0, joints_at_limit=joints_at_limit(km, q),
                    backend=backend, restarts=restarts)
