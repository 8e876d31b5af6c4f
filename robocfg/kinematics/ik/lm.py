"""``lm``: Levenberg–Marquardt IK with joint limits and random restarts inside a time budget.

Each descent drives ``e = log₆(M⁻¹·M*)`` — the SE(3) logarithm of the target pose seen from the
current frame (its angular part is the rotation error, rad) — to zero, using the frame Jacobian
in the LOCAL frame and the damping ``(JᵀJ + (μ·‖e‖² + λ₀)·I) Δq = Jᵀe`` (Sugihara's
error-dependent damping). Convergence is tested on the true residuals: ‖p* − p‖ (m) and the
rotation angle (rad). After each step,
wide/continuous joints are wrapped and the others clamped into their limits; a joint sitting on a
limit whose step points outwards is frozen for that step (an active set), so the descent slides
along the limits instead of stalling on them. A descent that stops making progress restarts from
the best of a few configurations drawn uniformly within the limits (TRAC-IK's idea), until the
tolerance is met or the time budget is spent. The best residual seen is returned either way.

The inner loop calls pinocchio's C++ kinematics and LAPACK directly: per iteration ≈ 15–30 µs.
"""

from __future__ import annotations

import math
from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from robocfg.geometry.lapack import lapack
from robocfg.kinematics.ik.common import (
    TWO_PI,
    finish,
    nearest_equivalent,
    prepare,
    search,
)
from robocfg.kinematics.ik.registry import register

dposv = lapack("dposv")  # scipy.linalg.lapack.dposv without importing scipy.linalg

if TYPE_CHECKING:
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel

_LOCAL = pin.ReferenceFrame.LOCAL


@register("lm")
class LMSolver:
    """Damped least squares (Levenberg–Marquardt) with an active set on the limits and restarts.

    ``tol_pos`` (m) and ``tol_rot`` (rad) define convergence. ``max_iter``: iterations per descent;
    a descent also ends when its error has not dropped by ``1 − stall_ratio`` for ``stall_n``
    iterations. ``restart_candidates``: random configurations scored by FK per restart.
    """

    name = "lm"
    clock = staticmethod(perf_counter)  # what the time budget is measured with (thread_time: CPU)

    def __init__(self, model: KinematicModel, tol_pos: float = 1e-5, tol_rot: float = 1e-5,
                 max_iter: int = 20, mu: float = 0.02, lambda0: float = 1e-6,
                 stall_ratio: float = 0.7, stall_n: int = 2, restart_candidates: int = 8,
                 max_total_iter: int | None = None):
        self.km = model
        self.max_total_iter = max_total_iter  # optional cap over all restarts (machine-independent budget)
        self.tol_pos, self.tol_rot = tol_pos, tol_rot
        self.max_iter, self.mu, self.lambda0 = max_iter, mu, lambda0
        self.stall_ratio, self.stall_n = stall_ratio, stall_n
        self.restart_candidates = restart_candidates
        # the damping system's matrix, rebuilt in place each iteration, and a view of its diagonal:
        # JᵀJ written into it and the damping added to the diagonal alone give the same floats as
        # JᵀJ + c·I (off the diagonal x + 0·c = x), without a 7×7 identity product and sum per step
        self._H = np.empty((model.nq, model.nq))
        self._H_diag = self._H.reshape(-1)[::model.nq + 1]
        # (q, position², rotation²) of each descent's best configuration in the current solve
        self._measured: list[tuple[np.ndarray, float, float]] = []

    def solve(self, target: np.ndarray, seed_q: np.ndarray, frame: str = "tcp",
              time_budget: float = 0.02, position_only: bool = False,
              rng: np.random.Generator | None = None) -> IKResult:
        t0 = perf_counter()
        km = self.km
        _, q0, fid, Mt = prepare(km, target, seed_q, frame)
        deadline = self.clock() + time_budget

        def descend(q: np.ndarray, deadline: float, cap: int | None) -> tuple[bool, int, float, np.ndarray]:
            return self._descend(q, Mt, fid, position_only, deadline, self.max_iter if cap is None else min(self.max_iter, cap))

        self._measured = []
        best_q, iters, restarts = search(km, descend, q0, deadline, rng, self.clock, self.max_total_iter,
                                         lambda rng: self._restart(rng, Mt, fid, position_only), whole_first=True)
        q = nearest_equivalent(km, best_q, q0)
        # the residuals the descent measured at this very configuration, if it did: finish needs no FK
        squared = None
        for qm, pe2, re2 in self._measured:
            if qm is best_q:
                squared = pe2, re2
                break
        self._measured = []
        if squared is not None and q is not best_q and not (q == best_q).all():
            squared = None  # a wrapped joint moved by 2π: measure it again
        return finish(km, self.name, q, Mt, fid, position_only, self.tol_pos, self.tol_rot, t0, iters, restarts,
                      squared)

    def _restart(self, rng: np.random.Generator, Mt: pin.SE3, fid: int, position_only: bool) -> np.ndarray:
        """The best of ``restart_candidates`` uniform configurations (position + 0.1·rotation error)."""
        km = self.km
        model, data = km.model, km.data
        cands = rng.uniform(km.lower, km.upper, (self.restart_candidates, km.nq))
        best, best_s = cands[0], math.inf
        for q in cands:
            pin.forwardKinematics(model, data, q)
            d = pin.updateFramePlacement(model, data, fid).actInv(Mt)
            t = d.translation
            s = t.dot(t)
            if not position_only:
                w = pin.log3(d.rotation)
                s += 0.1 * w.dot(w)
            if s < best_s:
                best, best_s = q, s
        return best

    def _descend(self, q: np.ndarray, Mt: pin.SE3, fid: int, position_only: bool, deadline: float,
                 max_iter: int | None = None):
        """One damped descent from ``q``: (converged, iterations, best squared error, best q); the
        best q's squared residuals are noted in ``_measured`` (``finish`` reuses them).

        Per iteration the few scalars (squared errors, damping) are Python floats and the 7×7
        system is built in place (``_H``): the same floats as numpy's 3-term dot products and
        ``JᵀJ + c·I`` with fewer calls. A step that stays within the limits (checked in Python
        floats) is not clamped: clamping would give back the same values."""
        km = self.km
        model, data = km.model, km.data
        lower, upper, wrap = km.lower, km.upper, km.wrap
        lo_list, hi_list = km.limit_lists
        any_wrap = km.any_wrap
        tp2, tr2 = self.tol_pos**2, self.tol_rot**2
        mu, lam0 = self.mu, self.lambda0
        ratio, stall_n = self.stall_ratio, self.stall_n
        H, H_diag = self._H, self._H_diag
        cjj, ufp, gfj, log6 = pin.computeJointJacobians, pin.updateFramePlacement, pin.getFrameJacobian, pin.log6
        mn, mx, nnz, dot = np.minimum, np.maximum, np.count_nonzero, np.dot
        clock = self.clock
        best_s, best_q, ref_s, stall = math.inf, q, math.inf, 0
        best_pe2 = best_re2 = math.inf
        pinned = False  # some joint sits on a limit (False for NaN, as numpy's comparisons)
        for a, v, b in zip(lo_list, q.tolist(), hi_list):  # noqa: B905 - nq values each
            if v <= a or v >= b:
                pinned = True
                break
        max_iter = self.max_iter if max_iter is None else max_iter
        it = 0
        for it in range(1, max_iter + 1):
            cjj(model, data, q)
            d = ufp(model, data, fid).actInv(Mt)
            t = d.translation
            x, y, z = t.tolist()
            pe2 = x * x + y * y + z * z  # t·t in Python floats, left to right
            if position_only:
                re2 = 0.0
                e = t
            else:
                e = log6(d).vector  # SE(3) log: its angular part is log3 of the rotation error
                _, _, _, x, y, z = e.tolist()
                re2 = x * x + y * y + z * z
            s = pe2 + re2
            if s < best_s:
                best_s, best_q, best_pe2, best_re2 = s, q, pe2, re2
            if pe2 <= tp2 and re2 <= tr2:
                self._measured.append((q, pe2, re2))
                return True, it, s, q
            if s < ref_s * ratio:
                ref_s, stall = s, 0
            else:
                stall += 1
                if stall >= stall_n:
                    break
            J = gfj(model, data, fid, _LOCAL)
            if position_only:
                J = J[:3]
            Jt = J.T
            dot(Jt, J, out=H)  # JᵀJ, symmetric to the bit
            H_diag += mu * s + lam0
            g = Jt.dot(e)
            dq = dposv(H, g)[1]
            froze = False
            if pinned:  # some joint sits on a limit: freeze those whose step points outwards
                blk = ((q <= lower) & (dq < 0)) | ((q >= upper) & (dq > 0))
                if nnz(blk):
                    froze = True
                    H[blk, :] = 0.0
                    H[:, blk] = 0.0
                    H[blk, blk] = 1.0
                    g[blk] = 0.0
                    dq = dposv(H, g)[1]
            qn = q + dq
            for a, v, b in zip(lo_list, qn.tolist(), hi_list):  # noqa: B905 - nq values each
                if not a <= v <= b:  # a joint left its limits (or NaN): clamp, wrap
                    q = mn(mx(qn, lower), upper)
                    if any_wrap:  # a wrapped joint leaving its (≥ 2π wide) range re-enters from the other side
                        over, under = (qn > upper) & wrap, (qn < lower) & wrap
                        if nnz(over) or nnz(under):
                            qn = qn - TWO_PI * over + TWO_PI * under
                            q = mn(mx(qn, lower), upper)
                    pinned = froze or q.tolist() != qn.tolist()
                    break
            else:  # within the limits: clamping would return the same values
                q = qn
                pinned = froze
            if clock() >= deadline:
                break
        if best_pe2 != math.inf:
            self._measured.append((best_q, best_pe2, best_re2))
        return False, it, best_s, best_q
