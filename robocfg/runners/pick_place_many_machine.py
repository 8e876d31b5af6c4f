"""One object's pick and place inside a ``pick_place_many`` episode, and what watches the episode.

:class:`ObjectMachine` is pick-place's state machine (:mod:`robocfg.runners.pick_place_machine`)
for an object already lying in a scene full of others, with two changes:

* **grasps in clutter**: every candidate grasp (from the object's geometry) is kept only if the
  whole arm and gripper, at the IK configurations of the grasp and of the pre-grasp above it, keep
  ``clutter_margin`` from the neighbouring objects, the fixtures and the obstacles
  (:class:`ClutterFilter`, pinocchio + coal on the robot's collision model; the object itself is
  left out). Among the kept ones the choice is pick-place's (least joint travel);
* **the place spot**: a bin spot is approached from ``lift_height`` above and left straight up,
  the hand turned about the object's vertical (or the object sent to a spare spot) so that the
  open hand clears the bin's walls and the objects already placed (:mod:`.pick_place_many_spot`); a
  shelf spot is entered ``place_clearance`` above its board (the planner finds the way in through
  the open front), lowered onto (the hand goes on down until the board carries the object:
  ``SET_DOWN_PRESS``), and left by lifting back to that height and withdrawing out of the front
  (phase ``withdraw``), planned collision-free.

:class:`ContactWatch` counts robot–fixture contacts in the simulation (every ``SETTLE_POLL``
physics steps), the figure that must stay 0. Frames: world, 4×4, metres.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from robocfg.geometry import quat_to_matrix, rotation_angle
from robocfg.grasp.object_grasp import LyingObject
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp
from robocfg.motion.moves import MoveFailed
from robocfg.runners.pick_place_grasp_choice import shifted as _shifted
from robocfg.runners.pick_place_machine import RELEASE_CLEARANCE, SETTLE_POLL, _StateMachine

if TYPE_CHECKING:
    from robocfg.planning.drive import PlannedDrive
    from robocfg.runners.pick_place_many_spot import BinWalls
    from robocfg.sim.world import World

CARRIED_OFF = 0.01  # m: a released object that rises this much during the retract went with the fingers
WITHDRAW_BEYOND = 0.12  # m: how far past a shelf's front edge the TCP withdraws
FINGER_CLEARANCE = 0.025  # m: fingertips above a placed object's top before withdrawing: the planner's 1 cm margin, the 5 mm position tolerance, 1 cm spare
# m: on a shelf board the hand goes this much further down than the object's lowest point needs to
# touch the board before the fingers open, so the board carries the object. An object let go while
# it hangs in the fingers (it slides a little in the grasp on the planned carry-in) can jam between
# the opening finger hulls: on the Panda both fingers stalled at 2/3 open, still pressing on it, and
# "did not come free" or rose with them on the retract.
SET_DOWN_PRESS = 0.0015
TOUCH = 0.0  # m: a reported robot–fixture point this close (or penetrating) is a contact


@dataclass(frozen=True)
class Spot:
    """Where one object goes: the support's top face under it (``z``, m), the unit vector out of
    the target through its open side (zero for a bin: open upwards), the distance (m) from the spot
    to that open side, and the underside of the board above (m; None for a bin)."""

    z: float
    front: np.ndarray
    to_front: float
    ceiling: float | None


@dataclass
class ContactWatch:
    """Counts polls (every ``SETTLE_POLL`` physics steps) at which the robot touches a fixture
    part or an obstacle, names the first such contact (phase, link, part) and tallies every
    poll's contacts by ``"phase: link touched part"`` (``by_kind``; a poll where two links touch
    counts once in ``count`` and once per pair in ``by_kind``).

    A contact is a point PyBullet reports at distance ≤ ``TOUCH`` (touching or penetrating).
    ``getContactPoints`` also returns the manifold's points that are still a few millimetres
    apart (measured: a Panda forearm 3.7–4.1 mm from a shelf side during a bin pick, 4.3 mm by
    the planner's own distance query): those are not contacts; the smallest such distance seen
    is kept in ``closest`` (m, None when no point was reported)."""

    world: World
    parts: list[str]
    phase: Callable[[], str]
    count: int = 0
    first: str | None = None
    by_kind: dict[str, int] = field(default_factory=dict)
    closest: float | None = None
    _steps: int = 0

    def on_step(self) -> None:
        self._steps += 1
        if self._steps % SETTLE_POLL:
            return
        robot = self.world.robot
        kinds: list[str] = []
        for part in self.parts:
            pts = self.world.contact_points(robot.body_id, part)
            if not pts:
                continue
            near = min(p.distance for p in pts)
            self.closest = near if self.closest is None else min(self.closest, near)
            for link in sorted({p.link_a for p in pts if p.distance <= TOUCH}):
                kinds.append(f"{self.phase()}: {robot.link_name(link)} touched {part}")
        if not kinds:
            return
        self.count += 1
        if self.first is None:
            self.first = kinds[0]
        for kind in kinds:
            self.by_kind[kind] = self.by_kind.get(kind, 0) + 1


@dataclass
class ClutterFilter:
    """Collision test of candidate grasps: ``drive`` is a planner's collision model of the scene
    (objects included) built with the clutter margin; ``rejected`` lists, per object, what the
    rejected candidates hit (first pair), for the failure message."""

    drive: PlannedDrive
    rejected: list[str] = field(default_factory=list)

    def free(self, world: World, target: str, q_pre: np.ndarray, q_grasp: np.ndarray) -> bool:
        """True if the arm and gripper at ``q_pre`` and ``q_grasp`` keep the margin from everything
        but ``target`` (the object being grasped)."""
        checker = self.drive.checker
        for q in (q_pre, q_grasp):
            if not checker.is_valid(q):
                hit = checker.contacts(q)
                self.rejected.append(hit[0].describe() if hit else "a pair within the margin")
                return False
        return True


class ObjectMachine(_StateMachine):
    """Pick-place of one object among others (see the module doc). ``body_id``: the object,
    already spawned; ``clutter``: the grasp filter (None: no filter); ``spot``: the place spot."""

    def __init__(self, world, arm, tools, params, setup, recorder, log, *, body_id: int, clutter: ClutterFilter | None,
                 spot: Spot, on_step: Callable[[], None] | None = None, place_clearance: float = 0.03,
                 walls: BinWalls | None = None):
        self._extra_step = on_step
        super().__init__(world, arm, tools, params, setup, recorder, log, body_id=body_id)
        self.clutter, self.spot, self.place_clearance = clutter, spot, place_clearance
        self.grasp: Grasp | None = None
        self.cost = math.inf  # joint travel (rad) of the chosen grasp
        self.candidates = 0
        self.rejected: list[str] = []  # what each candidate dropped for a collision hit (first pair)
        self.walls = walls  # a bin target's walls (None: no hand-clearance choice, e.g. a shelf)
        self.spare_xy: list[np.ndarray] = []  # free place spots (x, y, m) to fall back on, in order
        # spots off the grid (x, y, m) to try when no grid spot clears the hand (asked only then)
        self.off_grid: Callable[[], list[np.ndarray]] | None = None
        self.place_turn_deg = 0.0  # the hand's turn (deg) about the object's vertical at the place

    @property
    def in_collision(self) -> int:
        return len(self.rejected)

    def assign(self, place_xy: np.ndarray, spot: Spot) -> None:
        """Send the object to ``place_xy`` (x, y in m) on ``spot`` (forgets a chosen grasp)."""
        self.setup = dataclasses.replace(self.setup, place_xy=np.asarray(place_xy, float))
        self.spot, self.grasp = spot, None

    # ---- grasp choice ------------------------------------------------------------------------
    def plan_grasp(self) -> float:
        """Choose the grasp (clutter-filtered, least joint travel); return its travel (rad),
        inf when no candidate is reachable and collision-free."""
        pos, quat = self.world.body_pose(self.obj)
        self.R0 = quat_to_matrix(quat)
        lying = LyingObject(self.shape, pos, self.R0, self._support_height(pos[:2]))
        self.support_z = lying.support_z
        groups = self._grasp_groups(lying)
        if self.clutter is not None:
            self.clutter.drive.refresh_loose(self.world, ignore=(self.setup.body.name,))
            self.clutter.rejected.clear()
        self.candidates = sum(len(g) for g in groups)
        R_now = self.arm.ee_pose()[:3, :3]
        q0 = self.arm.joint_positions()
        self.grasp, self.cost = None, math.inf
        for group in groups:
            cands = sorted(group, key=lambda g: rotation_angle(R_now, g.rotation @ np.asarray(self.cfg.R_ee_graspnet)))
            scored = [(self._travel(g, q0), g) for g in cands]
            scored = [(c, g) for c, g in scored if c < math.inf]
            if scored:
                self.cost, self.grasp = min(scored, key=lambda t: t[0])
                break
        self.rejected = list(self.clutter.rejected) if self.clutter is not None else []
        if self.grasp is None and not groups:
            raise MoveFailed("grasp_choice", self._no_grasp_reason(lying))
        return self.cost

    def _travel(self, g: Grasp, q0: np.ndarray) -> float:
        """Largest joint change (rad) to the pre-grasp and on to the pose above the place point;
        inf when IK fails there or the grasp or pre-grasp configuration collides."""
        mover = self.mover
        T_pre = ee_pose_from_grasp(g, self.cfg, standoff=self.params.above_height)
        pre = self.model.ik(T_pre, seed_q=q0, frame="ee", time_budget=mover.ik_budget)
        if not pre.converged:
            return math.inf
        if self.clutter is not None:
            at = self.model.ik(ee_pose_from_grasp(g, self.cfg), seed_q=pre.q, frame="ee", time_budget=mover.ik_budget)
            if not at.converged or not self.clutter.free(self.world, self.setup.body.name, pre.q, at.q):
                return math.inf
        shift = np.array([*(self.setup.place_xy - g.center[:2]), 0.0])
        above = self.model.ik(_shifted(T_pre, shift), seed_q=pre.q, frame="ee", time_budget=mover.ik_budget)
        if not above.converged:
            return math.inf
        return max(float(np.max(np.abs(pre.q - q0))), float(np.max(np.abs(above.q - pre.q))))

    def grasp_failure(self) -> str:
        """Why no grasp was chosen: what the candidates collided with, or that IK missed them."""
        if self.rejected:
            common = max(sorted(set(self.rejected)), key=self.rejected.count)
            return (f"no collision-free grasp: {len(self.rejected)} of {self.candidates} candidates put the "
                    f"arm or gripper within the clutter margin (e.g. {common})")
        return f"no reachable grasp among {self.candidates} candidates"

    # ---- phases ------------------------------------------------------------------------------
    def run(self) -> None:
        p = self.params
        if self.grasp is None:
            self.plan_grasp()
        if self.grasp is None:
            raise MoveFailed("grasp_choice", self.grasp_failure())
        T_lift = self._pick(self.grasp)
        obj_now, quat_now = self.world.body_pose(self.obj)
        offset = self.arm.ee_pose()[:3, 3] - obj_now
        # its lowest point as it now hangs in the hand (it may have turned a little in the grasp)
        place_z = self.spot.z + self.shape.below_origin(quat_to_matrix(quat_now)) + RELEASE_CLEARANCE
        T_place = T_lift.copy()
        T_place[:3, 3] = np.array([*self.setup.place_xy, place_z]) + offset
        shelf = self.spot.ceiling is not None
        rise = self.place_clearance if shelf else p.lift_height
        if self.planned is not None:
            self._attach_held()
        self.begin("transport", "carry above the place spot")
        if not shelf and self.walls is not None:
            T_place = self._clear_of_walls(self.walls, T_place, max(rise, p.above_height, T_lift[2, 3] - T_place[2, 3]))
        T_above = _shifted(T_place, [0, 0, rise])
        if not shelf:
            T_above[2, 3] = max(T_lift[2, 3], T_above[2, 3])
        self._free_move(T_above, check=self._dropped, lines=(T_place,))
        self.begin("lower", "lower onto the support")
        self.mover.move(T_place, straight=True, check=self._dropped)
        if shelf:
            self._set_down()
        self.begin("release", "open the gripper")
        self.mover.max_acceleration = None
        self._release()
        if self.planned is not None:
            self.planned.detach(self.setup.body.name)
        z_released = float(self.world.body_pose(self.obj)[0][2])
        if shelf:
            up = max(rise, self._fingers_clear_height())
            self.begin("retract", "lift the fingers clear of the object")
            self.mover.move(_shifted(T_place, [0, 0, up]), straight=True, check=lambda: self._carried_off(z_released))
            self.begin("withdraw", "out of the shelf's front")
            out = self.spot.front * (self.spot.to_front + WITHDRAW_BEYOND)
            self._free_move(_shifted(T_place, [out[0], out[1], up]))
        else:
            self.begin("retract", "move up and away")
            self.mover.move(_shifted(T_place, [0, 0, p.above_height]), straight=True,
                            check=lambda: self._carried_off(z_released))
        self.close_phase(True)
        self.mover.settle(0.3)
        self._check_placed()

    def _clear_of_walls(self, walls: BinWalls, T_place: np.ndarray, top: float) -> np.ndarray:
        """The EE place pose at the assigned spot, or the first spare one (``spare_xy``), or one off
        the grid (``off_grid``), turned
        the least about the object's vertical so the open hand clears the bin's walls up to
        ``top`` m above it (:mod:`.pick_place_many_spot`); the spot taken becomes ``place_xy``."""
        spots = [self.setup.place_xy, *self.spare_xy]
        walls.see_objects(self.world, held=self.setup.body.name)
        choice = walls.choose(self.mover, T_place, self.setup.place_xy, spots, top, self.arm.joint_positions(),
                              self.off_grid)
        if choice.turn_deg or not np.allclose(choice.xy, self.setup.place_xy):
            off = "" if any(np.allclose(choice.xy, s) for s in spots) else " (off the grid: no grid spot fits)"
            self.log(f"  place: spot [{choice.xy[0]:.3f}, {choice.xy[1]:.3f}] m{off}, hand turned {choice.turn_deg:+.0f}° "
                     f"to keep the open hand clear of {walls.fixture!r}'s walls")
        self.setup = dataclasses.replace(self.setup, place_xy=choice.xy)
        self.place_turn_deg = choice.turn_deg
        return choice.T_place

    def _set_down(self) -> None:
        """Lower the hand (straight down, m) until the held object's lowest point is
        ``SET_DOWN_PRESS`` into the spot's board, so that the board, not the fingers, carries it
        when they open (see ``SET_DOWN_PRESS``)."""
        pos, quat = self.world.body_pose(self.obj)
        gap = float(pos[2]) - self.shape.below_origin(quat_to_matrix(quat)) - self.spot.z
        down = max(0.0, gap) + SET_DOWN_PRESS
        self.mover.move(_shifted(self.arm.ee_pose(), [0, 0, -down]), straight=True)

    def _carried_off(self, z_released: float) -> str | None:
        """Why the retract failed if the released object rose with the fingers (stuck to one)."""
        rise = float(self.world.body_pose(self.obj)[0][2]) - z_released
        return f"the released object rose {rise * 100:.1f} cm with the fingers" if rise > CARRIED_OFF else None

    def _fingers_clear_height(self) -> float:
        """How far (m) the TCP must rise from where it let go for the fingertips (at any opening,
        from the measured gripper boxes) to be ``FINGER_CLEARANCE`` above the object's top."""
        if self.boxes is None:
            return 0.0
        sweep = self.boxes.closing_sweep(None)
        tip = float(sweep.hi[sweep.finger, 0].max())  # m past the TCP along the approach (down)
        pos, quat = self.world.body_pose(self.obj)
        top = float(pos[2] + self.shape.posed(quat_to_matrix(quat))[:, 2].max())
        return top - (float(self.arm.tcp_pose()[2, 3]) - tip) + FINGER_CLEARANCE

    # ---- world helpers -----------------------------------------------------------------------
    def _support_height(self, xy: np.ndarray, jump_skipped: bool = False) -> float:
        """The place spot's board or floor (known exactly; a ray from above would find a shelf's
        top board), elsewhere the first surface below ``xy``."""
        if np.allclose(np.asarray(xy, float)[:2], self.setup.place_xy, atol=1e-9):
            return self.spot.z
        return super()._support_height(xy, jump_skipped)

    def _on_step(self) -> None:
        super()._on_step()
        if self._extra_step is not None:
            self._extra_step()
