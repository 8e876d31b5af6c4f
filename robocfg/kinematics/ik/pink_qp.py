"""``pink``: differential IK as a QP (pink + DAQP), integrated until the pose error is small.

Each iteration solves ``min ‖J Δq + e‖²_W + posture`` subject to configuration limits and
velocity limits (``dt`` = 1 s, so one iteration moves at most one second of joint travel), then
integrates. The posture task pulls towards the seed configuration (it keeps an elbow-up seed's
solution elbow-up) until the frame error drops below 1 mm / 0.01 rad, after which the frame task
alone finishes the job to the tolerance. Stalled descents restart within the time budget.

pink is imported when the solver is built.
"""

from __future__ import annotations

from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np

from robocfg.kinematics.ik.common import (
    Descent,
    finish,
    nearest_equivalent,
    prepare,
    search,
)
from robocfg.kinematics.ik.registry import register

if TYPE_CHECKING:
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel


@register("pink")
class PinkSolver:
    """pink FrameTask + PostureTask, DAQP, with ConfigurationLimit and VelocityLimit."""

    name = "pink"
    clock = staticmethod(perf_counter)  # what the time budget is measured with (thread_time: CPU)

    def __init__(self, model: KinematicModel, tol_pos: float = 1e-5, tol_rot: float = 1e-5,
                 max_iter: int = 100, posture_cost: float = 1e-3, dt: float = 1.0,
                 stall_ratio: float = 0.9, stall_n: int = 5, max_total_iter: int | None = None):
        import pink  # noqa: F401  (fail early if missing)
        from pink.limits import ConfigurationLimit, VelocityLimit

        self.km = model
        self.max_total_iter = max_total_iter  # cap over all restarts (see IKSolver)
        self.tol_pos, self.tol_rot = tol_pos, tol_rot
        self.max_iter, self.posture_cost, self.dt = max_iter, posture_cost, dt
        self.stall_ratio, self.stall_n = stall_ratio, stall_n
        self.limits = [ConfigurationLimit(model.model), VelocityLimit(model.model)]

    def solve(self, target: np.ndarray, seed_q: np.ndarray, frame: str = "tcp",
              time_budget: float = 0.02, position_only: bool = False,
              rng: np.random.Generator | None = None) -> IKResult:
        from pink.tasks import FrameTask, PostureTask

        t0 = perf_counter()
        km = self.km
        _, q0, fid, Mt = prepare(km, target, seed_q, frame)
        task = FrameTask(km.frame_name(frame), position_cost=1.0, orientation_cost=0.0 if position_only else 1.0)
        task.set_target(Mt)
        posture = PostureTask(cost=self.posture_cost)
        posture.set_target(q0)

        def descend(q: np.ndarray, deadline: float, cap: int | None):
            return self._descend(q, task, posture, Mt, fid, position_only, deadline, cap)

        best_q, iters, restarts = search(km, descend, q0, self.clock() + time_budget, rng, self.clock,
                                         self.max_total_iter)
        return finish(km, self.name, nearest_equivalent(km, best_q, q0), Mt, fid, position_only, self.tol_pos, self.tol_rot,
                      t0, iters, restarts)

    def _descend(self, q, task, posture, Mt, fid, position_only, deadline, cap: int | None = None):
        import pinocchio as pin
        from pink import Configuration, solve_ik
        from pink.exceptions import NoSolutionFound

        km = self.km
        conf = Configuration(km.model, km.data, q.copy(), copy_data=False)
        track = Descent(q, self.tol_pos, self.tol_rot, self.stall_ratio, self.stall_n)
        max_iter = self.max_iter if cap is None else min(self.max_iter, cap)
        for it in range(1, max_iter + 1):
            d = conf.data.oMf[fid].actInv(Mt)
            pe = float(np.linalg.norm(d.translation))
            re = 0.0 if position_only else float(np.linalg.norm(pin.log3(d.rotation)))
            done = track.step(conf.q.copy(), pe, re)
            if done is True:
                return True, it, pe + re, track.best_q
            if done is False or self.clock() >= deadline:
                return False, it, track.best_s, track.best_q
            tasks = [task, posture] if (pe > 1e-3 or re > 1e-2) else [task]
            try:
                v = solve_ik(conf, tasks, self.dt, solver="daqp", limits=self.limits, safety_break=False)
            except NoSolutionFound:  # infeasible QP: end this descent
                return False, it, track.best_s, track.best_q
            conf.integrate_inplace(v, self.dt)
            conf.update()
        return False, max_iter, track.best_s, track.best_q
