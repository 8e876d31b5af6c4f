"""One ``run grasp`` episode: perceive → plan antipodal grasps → execute the best → verify.

Let the spawned object settle, render the cameras, fuse and process the cloud, plan ranked
reachable grasps (``robocfg.grasp.antipodal``), then: pre-grasp (``pre_grasp_distance`` back
along the approach, a joint-space move) → approach (straight line) → close until held → lift
straight up → shake (±``shake_amplitude`` along y) → verify the object is still held and raised.
A failed attempt opens the gripper, returns home, re-perceives and tries the best grasp not near
one that already failed (``max_attempts`` in all). Grasp → EE target goes through
``ee_pose_from_grasp`` (``R_ee_graspnet``, ``ee_axis``, ``tcp_offset``).
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robocfg.config.commands import GraspParams
from robocfg.config.scene import Body
from robocfg.errors import PhaseFailed
from robocfg.geometry import rotation_angle
from robocfg.grasp.antipodal import Candidate, PlannerSettings, PlanResult, plan_grasps
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp
from robocfg.motion.moves import ArmMover, MoveFailed
from robocfg.runners.grasp_report import AttemptRecord, GraspEpisode, GraspTiming

if TYPE_CHECKING:
    from robocfg.engine.options import FrameRecorder
    from robocfg.grasp.cloud import Cloud
    from robocfg.grasp.gripper_model import GripperBoxes
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.limits import JointLimits
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World

Log = Callable[[str], None]
SPAWN_SETTLE = 0.6  # s the object is left to come to rest before perception
REACH_IK_BUDGET = 0.5  # s per IK call while ranking candidates; not consulted: the iteration bound ends the search
MAX_APPROACH_JUMP = 1.0  # rad: pre-grasp and grasp IK answers further apart are not one straight approach
FAILED_NEAR = 0.015  # m: candidates this close to a failed grasp (same object pose) are skipped
HALF_TURN = np.diag([1.0, -1.0, -1.0])  # about the approach axis: the same parallel-jaw grasp
# Bullet lets a lying cylinder creep and roll away on a level plane (measured: 10 cm in 3 s from
# rest); a little rolling/spinning friction (m) stops that artefact without changing the grasp.
ROLLING_FRICTION = 1e-3

EpisodeFailed = PhaseFailed  # perception or planning found nothing to try


@dataclass(frozen=True)
class EpisodeSetup:
    """Episode k's object (``objects[k % n]`` moved by ``randomize``) and the yaw added (rad)."""

    index: int
    seed: int
    body: Body
    yaw: float  # rad, added to the object's own yaw


@dataclass
class _Context:
    """Per-run objects shared by every episode."""

    world: World
    arm: ArmHandle
    params: GraspParams
    model: KinematicModel
    limits: JointLimits
    shake_limits: JointLimits
    boxes: GripperBoxes
    timing: GraspTiming
    save_cloud: Callable[[Cloud], None] | None


class _Episode:
    """One episode in the restored world: spawns the object, then attempts until lifted."""

    def __init__(self, ctx: _Context, setup: EpisodeSetup, recorder: FrameRecorder | None, log: Log | None):
        self.ctx, self.setup, self.recorder = ctx, setup, recorder
        self.world, self.arm, self.params = ctx.world, ctx.arm, ctx.params
        self.gripper = ctx.arm.require_gripper()
        self.log = log or (lambda _msg: None)
        self.rng = np.random.default_rng([setup.seed, 7])
        self.mover = ArmMover(self.world, self.arm, ctx.model, ctx.limits, self.params.position_tolerance,
                              self.params.orientation_tolerance, self.params.phase_timeout,
                              self._on_step if recorder is not None else None)
        self.obj = self.world.add_body(setup.body)
        self.world.set_dynamics(self.obj, rolling_friction=ROLLING_FRICTION, spinning_friction=ROLLING_FRICTION)
        self.attempts: list[AttemptRecord] = []
        self.failed: list[Grasp] = []
        self.first_plan: PlanResult | None = None
        self.n_points = 0
        self.lift_rise: float | None = None

    # ---- episode -----------------------------------------------------------------------------
    def run(self) -> GraspEpisode:
        failed, reason = None, "lifted"
        try:
            self.mover.settle(SPAWN_SETTLE)
            for k in range(self.params.max_attempts):
                cand = self._plan(k)
                try:
                    self._execute(cand, k)
                    self.attempts.append(AttemptRecord(cand.to_dict(), k, True, None, "lifted"))
                    failed, reason = None, "lifted"
                    break
                except MoveFailed as exc:
                    self.log(f"  attempt {k + 1} failed: {exc.phase}: {exc.reason}")
                    self.attempts.append(AttemptRecord(cand.to_dict(), k, False, exc.phase, exc.reason))
                    self.failed.append(cand.grasp)
                    failed, reason = exc.phase, exc.reason
                    self._recover()
        except PhaseFailed as exc:  # nothing to try (perception, planning), or recovery itself failed
            failed, reason = exc.phase, exc.reason
        return self._result(failed, reason)

    def _plan(self, attempt: int) -> Candidate:
        from robocfg.grasp.perception import perceive

        if self.recorder is not None:
            self.recorder.set_phase("plan")

        p, ctx = self.params, self.ctx
        t0 = time.perf_counter()
        per = perceive(self.world, p, self.rng)
        ctx.timing.perception.append(time.perf_counter() - t0)
        if attempt == 0:
            self.n_points = len(per.objects)
            if ctx.save_cloud is not None:
                ctx.save_cloud(per.objects)
                ctx.save_cloud = None
        if len(per.objects) < p.min_object_points:
            raise EpisodeFailed("perception", f"no object points in the workspace ({len(per.objects)} after "
                                              f"cropping to {p.workspace.min}..{p.workspace.max}, need ≥ {p.min_object_points})")
        settings = PlannerSettings(mu=p.friction, num_candidates=p.num_candidates, top_k=p.top_k,
                                   standoff=p.pre_grasp_distance, voxel=p.voxel_size)
        t0 = time.perf_counter()
        if per.objects.normals is None:
            raise EpisodeFailed("perception", "the object cloud has no normals")
        plan = plan_grasps(per.objects.points, per.objects.normals, per.scene, per.support_z, ctx.boxes,
                           settings, self.rng, reach=self._reach, curvature=per.objects.curvature)
        ctx.timing.planning.append(time.perf_counter() - t0)
        if self.first_plan is None:
            self.first_plan = plan
        usable = [c for c in plan.candidates if not any(np.linalg.norm(c.grasp.center - f.center) < FAILED_NEAR
                                                       and _same_axis(c.grasp, f) for f in self.failed)]
        from robocfg.grasp.draw import GraspRecorder

        if isinstance(self.recorder, GraspRecorder):
            self.recorder.show([c.grasp for c in plan.candidates], self.ctx.boxes, self.obj)
        self.log(f"Plan {attempt + 1}: {len(per.objects)} object points, {plan.poses} poses, "
                 f"{len(plan.candidates)} reachable candidates, best score "
                 f"{plan.candidates[0].score if plan.candidates else float('nan'):.3f} ({plan.time_s:.2f} s)")
        if not usable:
            counts = ", ".join(f"{k} {v}" for k, v in plan.rejected.items() if v)
            why = "every reachable candidate already failed" if plan.candidates else "no feasible grasp"
            raise EpisodeFailed("planning", f"{why}: {plan.seeds} seeds, {plan.poses} poses; rejected: "
                                            f"{counts or 'none'}; {plan.suppressed} duplicates suppressed")
        return usable[0]

    def _reach(self, g: Grasp) -> tuple[Grasp, np.ndarray] | None:
        """The half turn of ``g`` nearer the current wrist first; IK of the pre-grasp and the grasp."""
        cfg, model = self.arm.config, self.ctx.model
        R_now = self.arm.ee_pose()[:3, :3]
        R_eg = np.asarray(cfg.R_ee_graspnet, float)
        flips = [g, Grasp(g.center, g.rotation @ HALF_TURN, g.width)]
        flips.sort(key=lambda h: rotation_angle(R_now, h.rotation @ R_eg))
        q_now = self.arm.joint_positions()
        for h in flips:
            pre = model.ik(ee_pose_from_grasp(h, cfg, standoff=self.params.pre_grasp_distance), seed_q=q_now,
                           frame="ee", time_budget=REACH_IK_BUDGET)
            if not pre.converged:
                continue
            at = model.ik(ee_pose_from_grasp(h, cfg), seed_q=pre.q, frame="ee", time_budget=REACH_IK_BUDGET)
            if at.converged and np.max(np.abs(at.q - pre.q)) < MAX_APPROACH_JUMP:
                return h, pre.q
        return None

    def _execute(self, cand: Candidate, attempt: int) -> None:
        p, m, cfg = self.params, self.mover, self.arm.config
        g = cand.grasp
        T_grasp = ee_pose_from_grasp(g, cfg)
        T_pre = ee_pose_from_grasp(g, cfg, standoff=p.pre_grasp_distance)
        self._phase("pre_grasp", f"attempt {attempt + 1}: score {cand.score:.3f}, width {g.width * 1000:.0f} mm")
        self.gripper.open()
        m.move(T_pre, straight=False, q_goal=cand.q)
        self._phase("approach", "straight along the approach")
        m.move(T_grasp, straight=True)
        self._phase("grasp", "close the gripper")
        m.close_until_held(self.obj, timeout=1.5)
        self._phase("lift", f"lift {p.lift_height * 100:.0f} cm")
        z0 = self.world.body_pose(self.obj)[0][2]
        T_lift = T_grasp.copy()
        T_lift[2, 3] += p.lift_height
        m.move(T_lift, straight=True)
        self._check_lifted(z0, "lift")
        if p.shake:
            self._phase("shake", f"±{p.shake_amplitude * 100:.0f} cm along y, twice")
            m.limits = self.ctx.shake_limits
            try:
                for dy in (p.shake_amplitude, -p.shake_amplitude, p.shake_amplitude, -p.shake_amplitude, 0.0):
                    T = T_lift.copy()
                    T[1, 3] += dy
                    m.move(T, straight=True)
            finally:
                m.limits = self.ctx.limits
            m.settle(0.3)
            self._check_lifted(z0, "shake")

    def _check_lifted(self, z0: float, phase: str) -> None:
        z1 = self.world.body_pose(self.obj)[0][2]
        self.lift_rise = float(z1 - z0)
        if not self.gripper.is_grasping(self.obj) or self.lift_rise < 0.5 * self.params.lift_height:
            raise MoveFailed(phase, f"object not held (rose {self.lift_rise * 100:.1f} cm of {self.params.lift_height * 100:.0f})")

    def _recover(self) -> None:
        """Open, back off along the approach (or straight up), return home, let the object settle."""
        m = self.mover
        m.phase = "recover"
        m.open_gripper(0.3)
        T = self.arm.ee_pose()
        T[2, 3] += 0.1
        with contextlib.suppress(MoveFailed):  # going home in joint space is still safe from most poses
            m.move(T, straight=True)
        home = self.arm.home
        m.move(self.ctx.model.fk(home, "ee"), straight=False, q_goal=home)
        m.settle(0.3)

    def _phase(self, name: str, what: str) -> None:
        self.mover.phase = name
        if self.recorder is not None:
            self.recorder.set_phase(name)
        self.log(f"Phase {name.replace('_', '-')} — {what} (t = {self.world.t:.2f} s)")

    def _on_step(self) -> None:
        if self.recorder is not None:
            self.recorder.maybe_capture()

    def _result(self, failed: str | None, reason: str) -> GraspEpisode:
        s, plan = self.setup, self.first_plan
        b = s.body
        chosen = self.attempts[-1].candidate["score"] if self.attempts else None
        return GraspEpisode(
            index=s.index, seed=s.seed, object=b.name,
            object_start=[round(float(v), 6) for v in b.position],
            object_start_yaw_deg=round(math.degrees(s.yaw), 4),
            success=failed is None and bool(self.attempts) and self.attempts[-1].success,
            first_attempt_success=bool(self.attempts) and self.attempts[0].success,
            failed_phase=failed, reason=reason, object_points=self.n_points,
            poses_evaluated=plan.poses if plan else 0, candidates=len(plan.candidates) if plan else 0,
            rejected=dict(plan.rejected) if plan else {}, chosen_score=chosen,
            lift_rise=None if self.lift_rise is None else round(self.lift_rise, 6),
            sim_time=round(self.world.t, 6), attempts=self.attempts)


def _same_axis(a: Grasp, b: Grasp) -> bool:
    return abs(float(a.closing() @ b.closing())) > math.cos(math.radians(20)) and float(a.approach() @ b.approach()) > math.cos(math.radians(20))
