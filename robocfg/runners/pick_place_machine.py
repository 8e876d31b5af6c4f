"""The 8-phase pick-and-place state machine of one episode (``run pick-place``).

Every target comes from the robot YAML through one conversion: a GraspNet grasp chosen from the
object's real geometry and the gripper's measured one (:mod:`robocfg.grasp.object_grasp`) →
``ee_pose_from_grasp`` (``R_ee_graspnet``, ``ee_axis``, ``tcp_offset``) → IK (continuous along
straight TCP lines) → min-jerk timed joint trajectories → position drives, all through
:class:`robocfg.motion.moves.ArmMover`. With ``motion: reactive`` the two free-space moves
(pre-grasp, transport) are driven by the follow-target controller instead. The object is held by
friction only (parallel grippers) or by the suction cup. A phase that cannot complete raises
``MoveFailed(phase, reason)``; the episode then ends as a failed record.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from robocfg.assets.object_shape import object_shape
from robocfg.checks.grip_force import grip_budget
from robocfg.config.commands import PickPlaceParams
from robocfg.engine.session import silent
from robocfg.geometry import quat_to_matrix
from robocfg.grasp.object_grasp import LyingObject
from robocfg.kinematics.frames import Grasp
from robocfg.motion.moves import ArmMover, MoveFailed, grasp_hint
from robocfg.runners.pick_place_grasp_choice import GraspChoice, shifted
from robocfg.runners.pick_place_report import EpisodeResult, PhaseRecord
from robocfg.runners.pick_place_setup import EpisodeSetup, _Tools

Log = Callable[[str], None]
SETTLE_POLL = 4  # physics steps between checks while waiting
# m: how far above the support the object is let go — its lowest point as it hangs in the hand. A
# drop of a few mm sets an object rocking, and one standing on a narrow base (a duck on its belly)
# then topples after the fingers have left.
RELEASE_CLEARANCE = 0.001
# Bullet lets a ball or a lying cylinder creep and roll away on a level plane from rest; a little
# rolling/spinning friction (m) on round objects stops that artefact without changing the grasp.
ROLLING_FRICTION = 1e-3
REST_TOLERANCE = 1e-4  # m: an object spawned further than this from resting on its support is moved onto it
REST_CONTACT = 0.002  # m: an object no higher than this above resting on the support at the place point is set down
RELEASE_STILL = 1e-3  # opening fraction: fingers moving less than this per poll are not moving
RELEASE_STALL = 0.1  # s: fingers not moving this long, short of open, while opening have stalled


class _StateMachine(GraspChoice):
    def __init__(self, world, arm, tools: _Tools, params: PickPlaceParams, setup: EpisodeSetup, recorder,
                 log: Log | None, body_id: int | None = None):
        self.world, self.params, self.setup, self.recorder = world, params, setup, recorder
        self.log = log or silent
        self.logs = self.log is not silent  # False: no line is read, none is formatted
        self.arm, self.cfg, self.gripper = arm, arm.config, arm.require_gripper()
        self.model = tools.model
        self.reactive = tools.reactive
        self.planned = tools.planned
        if self.planned is not None:  # a failed episode may have left its object attached
            self.planned.detach(setup.body.name)
        # A per-step callback only where something samples the steps (a video recorder, or a
        # subclass's own ``_on_step``): without one the world steps in its bare loop.
        sampled = recorder is not None or type(self)._on_step is not _StateMachine._on_step
        self.mover = ArmMover(world, arm, tools.model, tools.limits, params.position_tolerance,
                              params.orientation_tolerance, on_step=self._on_step if sampled else None, phase="setup")
        if params.grip_force is not None:
            self.gripper.set_force(params.grip_force)
        self.shape = tools.shape or object_shape(setup.body, world.task.path.parent)
        self.boxes = tools.boxes
        self.pad_force = tools.pad_force
        self.obj = world.add_body(setup.body) if body_id is None else body_id  # body_id: already spawned
        if self.shape.symmetry != "none":
            world.set_dynamics(self.obj, rolling_friction=ROLLING_FRICTION, spinning_friction=ROLLING_FRICTION)
        self.R0 = self._rest_on_support()
        self.phases: list[PhaseRecord] = []
        self._phase: tuple[str, float] | None = None
        self.lift_rise: float | None = None

    # ---- phases ------------------------------------------------------------------------------
    def run(self) -> None:
        p = self.params
        self.gripper.open()
        self.mover.settle(0.2)
        obj_pos, obj_quat = self.world.body_pose(self.obj)
        self.R0 = quat_to_matrix(obj_quat)  # as it came to rest: what the place must reproduce
        lying = LyingObject(self.shape, obj_pos, quat_to_matrix(obj_quat), self._support_height(obj_pos[:2]))
        self.support_z = lying.support_z
        T_lift = self._pick(self._choose_grasp(lying))
        # Carry the object so that *it* lands on the place point: keep its offset from the EE.
        obj_now, quat_now = self.world.body_pose(self.obj)
        ee_now = self.arm.ee_pose()[:3, 3]
        offset = ee_now - obj_now
        # its lowest point as it now hangs in the hand (it may have turned a little in the grasp)
        below = self.shape.below_origin(quat_to_matrix(quat_now))
        place_z = self._support_height(self.setup.place_xy) + below + RELEASE_CLEARANCE
        place_obj = np.array([*self.setup.place_xy, place_z])
        T_place = T_lift.copy()
        T_place[:3, 3] = place_obj + offset
        T_above_place = T_place.copy()
        T_above_place[2, 3] = max(T_lift[2, 3], T_place[2, 3] + p.lift_height)
        if self.planned is not None:
            self._attach_held()
        self.begin("transport", "carry above the place point")
        self._free_move(T_above_place, check=self._dropped, lines=(T_place,))
        self.begin("lower", "lower onto the support")
        self.mover.move(T_place, straight=True, check=self._dropped_before_placed)
        self.begin("release", "open the gripper")
        self.mover.max_acceleration = None
        self._release()
        if self.planned is not None:
            self.planned.detach(self.setup.body.name)
        self.begin("retract", "move up and away")
        self.mover.move(shifted(T_place, [0, 0, p.above_height]), straight=True)
        self.close_phase(True)
        self.mover.settle(0.3)
        self._check_placed()

    def _pick(self, grasp: Grasp) -> np.ndarray:
        """Phases pre_grasp → approach → grasp → lift with ``grasp``, checked that the object rose
        with the hand; returns the EE pose where the lift ended (4×4, world)."""
        p = self.params
        T_pre, T_grasp = (T.copy() for T in self._grasp_poses(grasp))  # as the grasp choice weighed them
        self.begin("pre_grasp", "move above the object")
        T_lift = shifted(T_grasp, [0, 0, p.lift_height])
        self._free_move(T_pre, lines=(T_grasp, T_lift))
        self.begin("approach", "down to grasp height")
        self.mover.move(T_grasp, straight=True)
        self.begin("grasp", "close the gripper")
        self.mover.close_until_held(self.obj, p.timeouts.grasp)
        self._limit_acceleration()
        self.begin("lift", f"lift {p.lift_height * 100:.0f} cm")
        z0 = self.world.body_pose(self.obj)[0][2]
        self.mover.move(T_lift, straight=True)
        self._verify_lift(z0)
        return T_lift

    def begin(self, name: str, what: str) -> None:
        if self._phase is not None:
            self.close_phase(True)
        self._phase = (name, self.world.t)
        self.mover.phase, self.mover.timeout = name, getattr(self.params.timeouts, name, None)
        if self.recorder is not None:
            self.recorder.set_phase(name)
        if self.logs:
            self.log(f"Phase {len(self.phases) + 1}: {name.replace('_', '-')} — {what} (t = {self.world.t:.2f} s)")

    def close_phase(self, ok: bool, detail: str = "") -> None:
        if self._phase is None:
            return
        name, t0 = self._phase
        self.phases.append(PhaseRecord(name, round(t0, 6), round(self.world.t, 6), ok, detail))
        self._phase = None

    # ---- motion ------------------------------------------------------------------------------
    def _free_move(self, T: np.ndarray, check: Callable[[], str | None] | None = None,
                   lines: Sequence[np.ndarray] = ()) -> None:
        """A free-space move (pre-grasp, transport): joint-space trajectory or reactive controller.
        ``lines``: the EE poses the straight moves after it go to (planned mode: a goal
        configuration from which they have continuous IK is preferred)."""
        if self.planned is not None:
            self.planned.move(self.mover, T, check=check, lines=lines)
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

    def _rest_on_support(self) -> np.ndarray:
        """Put the object on the surface below it (its lowest point on the support, whatever its
        shape and the height the task gave) and return its rotation (3x3)."""
        pos, quat = self.world.body_pose(self.obj)
        R = quat_to_matrix(quat)
        below = self.shape.below_origin(R)
        self.support_z = float(pos[2]) - below  # as the task put it, if nothing is below
        z = self._support_height(pos[:2]) + below
        if abs(z - pos[2]) > REST_TOLERANCE:
            self.world.set_body_pose(self.obj, [pos[0], pos[1], z], quat)
        return R

    def _limit_acceleration(self) -> None:
        """Carry the object no harder than the grip holds it (:mod:`robocfg.checks.grip_force`):
        the timed moves that hold it (lift, transport, lower) keep the EE's acceleration within
        what friction at the gripper's force (the task's ``grip_force``, else ``max_force``) carries."""
        width = self.gripper.width()
        if width is None:
            return
        body = self.setup.body
        budget = grip_budget(self.cfg, self.pad_force, body.mass, body.friction, width)
        if budget is None:
            return
        if self.params.grip_force is not None:  # the task's force instead of the limit: the pad force scales with it
            budget = replace(budget, pad_force=budget.pad_force * self.params.grip_force / budget.limit)
        a = budget.max_acceleration()
        self.mover.max_acceleration = a
        if self.logs:
            self.log(f"  grip: {budget.pad_force:.1f} N per pad at {width * 1000:.0f} mm; the held object may "
                     f"be accelerated up to {a:.1f} m/s²")

    def _release(self) -> None:
        """Open until the object is free and the fingers are 90 % open. Opening rebuilds the
        fingers' contacts with what they touch (:meth:`robocfg.sim.gripper.parallel.ParallelGripper.open`:
        PyBullet can keep a contact point whose normal turned round, which drags the object with
        an opening finger or holds the fingers shut; done where the command reaches the drives,
        so a dataset replay does it at the same step). As a last resort, not replayed (an episode
        where it fires does not replay bit-exactly, and the log says so): fingers that still stop
        short of open (``RELEASE_STALL`` s without moving) while the object is between them get
        their contacts with it rebuilt again (:meth:`~robocfg.sim.gripper.base.Gripper.refresh_contacts`),
        and so do fingers open but still touching it, before the hand moves away (such a point
        drags the object up with them)."""
        t0 = self.world.t
        self.gripper.open()
        now = last = self.gripper.fraction()  # the opening measured once per poll (no joint moves between)
        still = 0.0
        while now < 0.9 or self._held():  # the contact query (a pure read) only once the fingers are 90 % open
            if self.world.t - t0 > self.params.timeouts.release:
                raise MoveFailed("release", "the object did not come free")
            self.mover.step(SETTLE_POLL)
            now = self.gripper.fraction()
            still = still + SETTLE_POLL * self.world.dt if abs(now - last) < RELEASE_STILL else 0.0
            last = now
            if still >= RELEASE_STALL and self.gripper.refresh_contacts(self.obj):
                self.log(f"  release: the fingers stopped at {now:.0%} open; their contacts with the object rebuilt "
                         "(not replayed by a dataset replay)")
                still = 0.0
        if self.gripper.refresh_contacts(self.obj, touching_only=True):
            self.log("  release: a finger still touched the object when open; its contacts rebuilt (not replayed by "
                     "a dataset replay)")

    def _dropped(self) -> str | None:
        if self._held():
            return None
        return f"object dropped ({self._object_to_tcp() * 100:.1f} cm from the TCP)"

    def _dropped_before_placed(self) -> str | None:
        """While lowering: a drop, unless the object already rests on the support at the place
        point (within ``success_tolerance``), touched down a moment early — one jaw of a one-jaw
        gripper can leave it as the floor takes its weight. The final check still judges the place."""
        why = self._dropped()
        if why is None:
            return None
        pos, quat = self.world.body_pose(self.obj)
        rest_z = self._support_height(self.setup.place_xy) + self.shape.below_origin(quat_to_matrix(quat))
        at_place = float(np.linalg.norm(pos[:2] - self.setup.place_xy)) <= self.params.success_tolerance
        return None if at_place and pos[2] - rest_z <= REST_CONTACT else why  # on it, or pressed into it

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
        if self.recorder is not None:
            self.recorder.maybe_capture()

    def _support_height(self, xy: np.ndarray, jump_skipped: bool = False) -> float:
        """Height (m) of the first surface below ``xy`` that is not the robot or the object. The ray
        is vertical, so its hits come highest first and the first one not skipped is the highest of
        them: the casts stop there. ``jump_skipped``: see
        :meth:`~robocfg.sim.queries.SceneQueries.first_ray_hit` (the same surface; its height's
        last bits may differ): only for heights that go to a check, never to what is simulated."""
        skip = {self.obj, *(r.body_id for r in self.world.robots)}
        z = 0.0 if self.world.task.config.scene.ground else -math.inf
        hit = self.world.first_ray_hit([xy[0], xy[1], 5.0], [xy[0], xy[1], -1.0], skip, jump_skipped=jump_skipped)
        if hit is not None:
            z = max(z, hit.position[2])
        return z if math.isfinite(z) else self.support_z

    def _check_placed(self) -> None:
        p = self.params
        pos, quat = self.world.body_pose(self.obj)
        err = float(np.linalg.norm(pos[:2] - self.setup.place_xy))
        R = quat_to_matrix(quat)
        tilt = self.shape.tilt_deg(self.R0, R)  # as _tilt(quat)
        # the hand hovers above the place point: the ray starts below it (a 1 cm check)
        rest_z = self._support_height(self.setup.place_xy, jump_skipped=True) + self.shape.below_origin(R)
        if err > p.success_tolerance:
            raise MoveFailed("place", f"object {err * 100:.1f} cm from the place point (tolerance {p.success_tolerance * 100:.1f} cm)")
        if tilt > p.max_tilt_deg:
            raise MoveFailed("place", f"object tilted {tilt:.1f}° (max {p.max_tilt_deg:.0f}°)")
        if abs(pos[2] - rest_z) > 0.01:
            raise MoveFailed("place", f"object not resting on the support (centre {pos[2] * 100:.1f} cm, expected {rest_z * 100:.1f} cm)")

    def _tilt(self, quat) -> float:
        """Degrees the object has tipped from how it lay at the start (yaw free; see
        :meth:`~robocfg.assets.object_shape.ObjectShape.tilt_deg`); NaN for a diverged body's
        non-finite quaternion (the episode failed with ``PhysicsDiverged``: its record is still made)."""
        if not all(math.isfinite(v) for v in quat):
            return math.nan
        return self.shape.tilt_deg(self.R0, quat_to_matrix(quat))

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
