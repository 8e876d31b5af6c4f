"""The 8-phase pick-and-place state machine of one episode (``run pick-place``).

Every target comes from the robot YAML through one conversion: a top-down GraspNet grasp
(approach straight down, fingers closing across the object's narrower horizontal side) →
``ee_pose_from_grasp`` (``R_ee_graspnet``, ``ee_axis``, ``tcp_offset``) → IK (continuous along
straight TCP lines) → min-jerk timed joint trajectories → position drives, all through
:class:`robocfg.motion.moves.ArmMover`. With ``motion: reactive`` the two free-space moves
(pre-grasp, transport) are driven by the follow-target controller instead. The object is held by
friction only (parallel grippers) or by the suction cup. A phase that cannot complete raises
``MoveFailed(phase, reason)``; the episode then ends as a failed record.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robocfg.config.commands import PickPlaceParams
from robocfg.config.scene import Body
from robocfg.geometry import rotation_angle
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp, top_down_grasps
from robocfg.motion.moves import ArmMover, MoveFailed, grasp_hint
from robocfg.runners.pick_place_report import EpisodeResult, PhaseRecord

if TYPE_CHECKING:
    from robocfg.sim.world import World

Log = Callable[[str], None]
SETTLE_POLL = 4  # physics steps between checks while waiting
RELEASE_CLEARANCE = 0.004  # m: how far above the support the object is let go
SUCTION_PRESS = 0.002  # m: a suction cup is driven this far into the top face


@dataclass(frozen=True)
class EpisodeSetup:
    """What an episode randomised: object body, its yaw (rad), place point (x, y in m), seed."""

    index: int
    seed: int
    body: Body
    yaw: float  # rad
    place_xy: np.ndarray


@dataclass(frozen=True)
class _Tools:
    """Per-run helpers shared by every episode: kinematic model, scaled joint limits and, with
    ``motion: reactive``, the follow-target controller driving the free-space moves (with ``motion:
    planned``, the global planner)."""

    model: Any
    limits: Any
    reactive: Any = None
    planned: Any = None  # motion: planned — a robocfg.planning.drive.PlannedDrive


def reactive_drive(robot, world: World, arm_name: str, params: PickPlaceParams):
    """The controller for ``motion: reactive`` (built once per run: it is expensive), else None."""
    if params.motion != "reactive":
        return None
    from robocfg.motion.reactive_drive import bounding_radius, build_reactive_drive

    obj = params.object  # held object's centre beyond the TCP, along the tool axis (m)
    beyond = obj.half_height() - SUCTION_PRESS if world.robot.arm(arm_name).require_gripper().grasps_at_surface else params.grasp_depth
    return build_reactive_drive(robot, world, arm_name, velocity_scale=params.speed_scale,
                                payload=(beyond, bounding_radius(obj)))


def planned_drive(robot, world: World, model, params: PickPlaceParams):
    """The global planner for ``motion: planned`` (built once per run), else None."""
    if params.motion != "planned":
        return None
    from robocfg.planning.drive import build_planned_drive

    return build_planned_drive(robot, world, model)


class _StateMachine:
    def __init__(self, world, arm, tools: _Tools, params: PickPlaceParams, setup: EpisodeSetup, recorder,
                 log: Log | None):
        self.world, self.params, self.setup, self.recorder = world, params, setup, recorder
        self.log = log or (lambda _msg: None)
        self.arm, self.cfg, self.gripper = arm, arm.config, arm.require_gripper()
        self.model = tools.model
        self.reactive = tools.reactive
        self.planned = tools.planned
        if self.planned is not None:  # a failed episode may have left its object attached
            self.planned.detach(setup.body.name)
        self.mover = ArmMover(world, arm, tools.model, tools.limits, params.position_tolerance,
                              params.orientation_tolerance, on_step=self._on_step, phase="setup")
        if params.grip_force is not None:
            self.gripper.set_force(params.grip_force)
        self.obj = world.add_body(setup.body)
        self.phases: list[PhaseRecord] = []
        self._phase: tuple[str, float] | None = None
        self.lift_rise: float | None = None
        self.sink = None  # a dataset EpisodeRecorder: sees every physics step

    # ---- phases ------------------------------------------------------------------------------
    def run(self) -> None:
        p = self.params
        self.gripper.open()
        self.mover.settle(0.2)
        obj_pos, _ = self.world.body_pose(self.obj)
        self.support_z = obj_pos[2] - self.setup.body.half_height()
        if self.gripper.grasps_at_surface:  # a cup touches the top face, pressing in slightly
            center = obj_pos + np.array([0, 0, self.setup.body.half_height() - SUCTION_PRESS])
        else:
            center = obj_pos + np.array([0, 0, p.grasp_depth])
        grasp = self._choose_grasp(center)
        T_grasp = ee_pose_from_grasp(grasp, self.cfg)
        T_pre = ee_pose_from_grasp(grasp, self.cfg, standoff=p.above_height)

        self.begin("pre_grasp", "move above the object")
        self._free_move(T_pre)
        self.begin("approach", "down to grasp height")
        self.mover.move(T_grasp, straight=True)
        self.begin("grasp", "close the gripper")
        self.mover.close_until_held(self.obj, self.mover.timeout)
        self.begin("lift", f"lift {p.lift_height * 100:.0f} cm")
        z0 = self.world.body_pose(self.obj)[0][2]
        T_lift = _shifted(T_grasp, [0, 0, p.lift_height])
        self.mover.move(T_lift, straight=True)
        self._verify_lift(z0)
        # Carry the object so that *it* lands on the place point: keep its offset from the EE.
        obj_now = self.world.body_pose(self.obj)[0]
        ee_now = self.arm.ee_pose()[:3, 3]
        offset = ee_now - obj_now
        place_z = self._support_height(self.setup.place_xy) + self.setup.body.half_height() + RELEASE_CLEARANCE
        place_obj = np.array([*self.setup.place_xy, place_z])
        T_place = T_lift.copy()
        T_place[:3, 3] = place_obj + offset
        T_above_place = T_place.copy()
        T_above_place[2, 3] = max(T_lift[2, 3], T_place[2, 3] + p.lift_height)
        if self.planned is not None:
            self._attach_held()
        self.begin("transport", "carry above the place point")
        self._free_move(T_above_place, check=self._dropped)
        self.begin("lower", "lower onto the support")
        self.mover.move(T_place, straight=True, check=self._dropped)
        self.begin("release", "open the gripper")
        self._release()
        if self.planned is not None:
            self.planned.detach(self.setup.body.name)
        self.begin("retract", "move up and away")
        self.mover.move(_shifted(T_place, [0, 0, p.above_height]), straight=True)
        self.close_phase(True)
        self.mover.settle(0.3)
        self._check_placed()

    def begin(self, name: str, what: str) -> None:
        if self._phase is not None:
            self.close_phase(True)
        self._phase = (name, self.world.t)
        self.mover.phase, self.mover.timeout = name, getattr(self.params.timeouts, name)
        if self.recorder is not None:
            self.recorder.set_phase(name)
        n = len(self.phases) + 1
        self.log(f"Phase {n}: {name.replace('_', '-')} — {what} (t = {self.world.t:.2f} s)")

    def close_phase(self, ok: bool, detail: str = "") -> None:
        if self._phase is None:
            return
        name, t0 = self._phase
        self.phases.append(PhaseRecord(name, round(t0, 6), round(self.world.t, 6), ok, detail))
        self._phase = None

    # ---- motion ------------------------------------------------------------------------------
    def _free_move(self, T: np.ndarray, check: Callable[[], str | None] | None = None) -> None:
        """A free-space move (pre-grasp, transport): joint-space trajectory or reactive controller."""
        if self.planned is not None:
            self.planned.move(self.mover, T, check=check)
        elif self.reactive is None:
            self.mover.move(T, straight=False, check=check)
        else:
            self.mover.move_reactive(T, self.reactive, check=check)

    def _attach_held(self) -> None:
        """Give the planner the held object, where it now sits in the hand."""
        from robocfg.geometry import quat_to_matrix

        pos, quat = self.world.body_pose(self.obj)
        T_obj = np.eye(4)
        T_obj[:3, :3], T_obj[:3, 3] = quat_to_matrix(quat), pos
        self.planned.attach(self.setup.body.name, self.setup.body, np.linalg.inv(self.arm.ee_pose()) @ T_obj)

    def _choose_grasp(self, center: np.ndarray) -> Grasp:
        """Of the two top-down grasps, the one needing the least joint travel (largest |Δq|, rad)
        to reach the pre-grasp pose and from there the pose above the place point; the smaller
        wrist turn breaks ties. (IK can land on a far branch for one of the two, e.g. a Panda's
        shoulder flipped by ≈ 3 rad, or a wrist that must wind round a joint limit to carry.)"""
        b = self.setup.body
        extent = (b.size[0], b.size[1]) if b.shape in ("box", "mesh") else (2 * b.size[0], 2 * b.size[0])
        R_now = self.arm.ee_pose()[:3, :3]
        cands = sorted(top_down_grasps(center, self.setup.yaw, extent),
                       key=lambda g: rotation_angle(R_now, g.rotation @ np.asarray(self.cfg.R_ee_graspnet)))
        q0 = self.arm.joint_positions()
        shift = np.array([*(self.setup.place_xy - center[:2]), 0.0])

        def travel(g: Grasp) -> float:
            T_pre = ee_pose_from_grasp(g, self.cfg, standoff=self.params.above_height)
            cost, q = 0.0, q0
            for T in (T_pre, _shifted(T_pre, shift)):
                res = self.model.ik(T, seed_q=q, frame="ee", time_budget=self.mover.ik_budget)
                if not res.converged:
                    return math.inf
                cost, q = max(cost, float(np.max(np.abs(res.q - q)))), res.q
            return cost

        costs = [travel(g) for g in cands]
        return cands[int(np.argmin(costs))] if min(costs) < math.inf else cands[0]

    def _release(self) -> None:
        t0 = self.world.t
        self.gripper.open()
        while self._held() or self.gripper.fraction() < 0.9:
            if self.world.t - t0 > self.mover.timeout:
                raise MoveFailed("release", "the object did not come free")
            self.mover.step(SETTLE_POLL)

    def _dropped(self) -> str | None:
        if self._held():
            return None
        return f"object dropped ({self._object_to_tcp() * 100:.1f} cm from the TCP)"

    def _held(self) -> bool:
        return bool(self.gripper.is_grasping(self.obj))

    def _object_to_tcp(self) -> float:
        return float(np.linalg.norm(self.world.body_pose(self.obj)[0] - self.arm.tcp_pose()[:3, 3]))

    def _verify_lift(self, z0: float) -> None:
        z1 = self.world.body_pose(self.obj)[0][2]
        self.lift_rise = float(z1 - z0)
        want = 0.5 * self.params.lift_height
        if not self._held() or self.lift_rise < want:
            below = self.arm.tcp_pose()[2, 3] - z1
            hint = grasp_hint(self.arm, self.gripper.width())
            raise MoveFailed("lift", f"object slipped, {below * 100:.1f} cm below the fingers (rose {self.lift_rise * 100:.1f} cm)"
                             + (f"; {hint}" if hint else ""))

    # ---- world helpers -----------------------------------------------------------------------
    def _on_step(self) -> None:
        if self.sink is not None:
            self.sink.on_step()
        if self.recorder is not None:
            self.recorder.maybe_capture()

    def _support_height(self, xy: np.ndarray) -> float:
        """Height (m) of the first surface below ``xy`` that is not the robot or the object."""
        skip = {self.obj, *(r.body_id for r in self.world.robots)}
        z = 0.0 if self.world.task.config.scene.ground else -math.inf
        for hit in self.world.ray_hits([xy[0], xy[1], 5.0], [xy[0], xy[1], -1.0]):
            if hit.body not in skip:
                z = max(z, hit.position[2])
        return z if math.isfinite(z) else self.support_z

    def _check_placed(self) -> None:
        p = self.params
        pos, quat = self.world.body_pose(self.obj)
        err = float(np.linalg.norm(pos[:2] - self.setup.place_xy))
        tilt = self._tilt(quat)
        rest_z = self._support_height(self.setup.place_xy) + self.setup.body.half_height()
        if err > p.success_tolerance:
            raise MoveFailed("place", f"object {err * 100:.1f} cm from the place point (tolerance {p.success_tolerance * 100:.1f} cm)")
        if tilt > p.max_tilt_deg:
            raise MoveFailed("place", f"object tilted {tilt:.1f}° (max {p.max_tilt_deg:.0f}°)")
        if abs(pos[2] - rest_z) > 0.01:
            raise MoveFailed("place", f"object not resting on the support (centre {pos[2] * 100:.1f} cm, expected {rest_z * 100:.1f} cm)")

    @staticmethod
    def _tilt(quat) -> float:
        from robocfg.geometry import quat_to_matrix

        z = quat_to_matrix(quat)[:, 2]
        return math.degrees(math.acos(max(-1.0, min(1.0, float(z[2])))))

    def result(self, failed: str | None, reason: str) -> EpisodeResult:
        pos, quat = self.world.body_pose(self.obj)
        b, s = self.setup.body, self.setup
        err = float(np.linalg.norm(pos[:2] - s.place_xy))
        return EpisodeResult(
            index=s.index, seed=s.seed, success=failed is None, failed_phase=failed, reason=reason,
            object_start=[round(float(v), 6) for v in b.position],
            object_start_yaw_deg=round(math.degrees(s.yaw), 4),
            place_target=[round(float(v), 6) for v in s.place_xy],
            object_final=[round(float(v), 6) for v in pos],
            place_error=round(err, 6), tilt_deg=round(self._tilt(quat), 4),
            lift_rise=None if self.lift_rise is None else round(self.lift_rise, 6),
            mass=round(b.mass, 6), friction=round(b.friction, 6),
            sim_time=round(self.world.t, 6), steps=self.world.steps, phases=self.phases,
        )


def _shifted(T: np.ndarray, d) -> np.ndarray:
    out = T.copy()
    out[:3, 3] += np.asarray(d, float)
    return out


