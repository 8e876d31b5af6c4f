"""Which grasp a pick-place episode uses: candidates from the object's geometry
(:mod:`robocfg.grasp.object_grasp`: top-down groups, antipodal pairs on a mesh, the top face for
a suction cup), then, within the first group the arm can reach, the one needing the least joint
travel and whose straight approach and lower lines have continuous IK.

A base class of the episode's state machine (:class:`robocfg.runners.pick_place_machine._StateMachine`
and its several-object subclass): the choice reads the episode's arm, model, mover and measured
gripper, declared below, and is kept here because it is one concept of its own (≈ 100 lines).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

import numpy as np

from robocfg.config.commands import PickPlaceParams
from robocfg.geometry import rotation_angle
from robocfg.grasp.gripper_model import GripperBoxes
from robocfg.grasp.object_grasp import (
    LyingObject,
    iter_top_down_groups,
    mesh_grasps,
    suction_grasps,
    usable_width,
)
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp
from robocfg.motion.moves import ArmMover, MoveFailed
from robocfg.runners.pick_place_setup import SUCTION_PRESS, EpisodeSetup

if TYPE_CHECKING:
    from robocfg.config.robot import ArmConfig
    from robocfg.sim.gripper.base import Gripper
    from robocfg.sim.robot import ArmHandle


class GraspChoice:
    """The grasp-choosing part of one episode (set by the state machine's ``__init__``)."""

    arm: ArmHandle
    cfg: ArmConfig
    params: PickPlaceParams
    setup: EpisodeSetup
    model: Any  # robocfg.kinematics.model.KinematicModel
    mover: ArmMover
    gripper: Gripper
    boxes: GripperBoxes | None

    def _choose_grasp(self, lying: LyingObject) -> Grasp:
        """A grasp chosen from the object's geometry (:mod:`robocfg.grasp.object_grasp`): groups of
        candidates, best first; within the first group that the arm can reach, the one needing the
        least joint travel (largest |Δq|, rad) to reach the pre-grasp pose and from there the pose
        above the place point, among those whose straight approach and lower lines have continuous
        IK when there are any; the smaller wrist turn breaks ties. (IK can land on a far branch for
        one of two half-turn twins, e.g. a Panda's shoulder flipped by ≈ 3 rad, or a wrist that
        must wind round a joint limit to carry.)"""
        first: list[Grasp] | None = None
        R_ee_graspnet = np.asarray(self.cfg.R_ee_graspnet)
        for group in self._iter_grasp_groups(lying):  # searched one at a time: usually the first will do
            if first is None:
                first = group
                R_now = self.arm.ee_pose()[:3, :3]
                q0 = self.arm.joint_positions()
            cands = sorted(group, key=lambda g: rotation_angle(R_now, g.rotation @ R_ee_graspnet))
            reach = _Reach(self, cands, q0)
            cheapest: int | None = None
            # The least travel among those whose lines are continuous (ties: the smaller wrist turn),
            # else the least travel: the lines (the costly part, IK every 3 cm) are checked in order
            # of travel, only until one candidate passes.
            for i in reach.order():
                cheapest = i if cheapest is None else cheapest
                if all(self._line_continuous(q, T_down) for q, T_down in reach.lines[i]):
                    return cands[i]
            if cheapest is not None:
                return cands[cheapest]
        if first is None:
            raise MoveFailed("grasp_choice", self._no_grasp_reason(lying))
        return first[0]

    def _grasp_poses(self, g: Grasp) -> tuple[np.ndarray, np.ndarray]:
        """(EE pose at the pre-grasp stand-off, EE pose at the grasp) of ``g`` (4x4, world,
        read-only): computed once an episode per grasp (the choice weighs them and the pick then
        moves to the chosen grasp's)."""
        kept: dict[int, tuple[Grasp, np.ndarray, np.ndarray]] = self.__dict__.setdefault("_poses_of_grasps", {})
        entry = kept.get(id(g))
        if entry is None or entry[0] is not g:
            T_pre = ee_pose_from_grasp(g, self.cfg, standoff=self.params.above_height)
            T_grasp = ee_pose_from_grasp(g, self.cfg)
            T_pre.setflags(write=False)
            T_grasp.setflags(write=False)
            entry = kept[id(g)] = (g, T_pre, T_grasp)  # the grasp kept with them: its id is not reused
        return entry[1], entry[2]

    def _line_continuous(self, q: np.ndarray, T_goal: np.ndarray) -> bool:
        """Whether the straight EE line from FK(``q``) down to ``T_goal`` (the approach, or the
        lower at the place point) has continuous IK: a candidate whose line crosses a wrist or
        shoulder branch would fail there, so its twin is preferred."""
        try:
            self.mover.straight_waypoints(q, T_goal)
        except MoveFailed:
            return False
        return True

    def _grasp_groups(self, lying: LyingObject) -> list[list[Grasp]]:
        """Candidate grasps from the object's geometry, grouped, best group first."""
        return list(self._iter_grasp_groups(lying))

    def _iter_grasp_groups(self, lying: LyingObject) -> Iterator[list[Grasp]]:
        """:meth:`_grasp_groups` one group at a time (a top-down group's height is searched when
        it is asked for)."""
        p = self.params
        if self.gripper.grasps_at_surface:  # a cup touches the top face, pressing in slightly
            yield suction_grasps(lying, SUCTION_PRESS)
            return
        if self.boxes is None:
            raise MoveFailed("grasp_choice", "the gripper's geometry was not measured")
        if self.setup.body.shape == "mesh":  # drawn first, as before the top-down groups
            rng = np.random.default_rng([self.setup.seed, 1])
            for g in mesh_grasps(lying, self.boxes, rng, p.above_height):
                yield [g, half_turn(g)]
        for grp in iter_top_down_groups(lying, self.boxes):
            if p.grasp_depth is not None:  # the task fixes the TCP height relative to the object's centre
                z = float(lying.position[2]) + p.grasp_depth
                grp = [Grasp(np.array([*g.center[:2], z]), g.rotation, g.width) for g in grp]
            yield grp

    def _no_grasp_reason(self, lying: LyingObject) -> str:
        if self.boxes is None:
            return "no grasp found"
        narrow = lying.shape.min_horizontal_width(lying.rotation)
        usable = usable_width(self.boxes)
        if narrow > usable:
            return (f"no grasp found: the object ({narrow * 1000:.1f} mm across its narrowest horizontal side) "
                    f"does not fit the open fingers ({usable * 1000:.1f} mm usable)")
        sweep = self.boxes.closing_sweep(narrow)
        tip = float(sweep.hi[sweep.finger, 0].max())
        return (f"no grasp height: closing to {narrow * 1000:.1f} mm the fingertips reach {tip * 1000:.0f} mm past the "
                f"TCP, so with them above the support and the palm above the object's top the pads cannot reach the "
                f"object ({(lying.top_z - lying.bottom_z) * 1000:.0f} mm tall)")


class _Reach:
    """The joint travel of a group's candidates (rad): for each, the largest |Δq| of its two legs,
    IK from the current joints ``q0`` to the pre-grasp pose, then from there to the same pose above
    the place point (each leg's answer is a straight line's start, down to the grasp or the place
    height). The first leg of every candidate is solved at once; a second leg only when its
    candidate could still come next in the order of travel (the first leg bounds the travel from
    below), so candidates that cannot win cost one IK solve instead of two. The same order as
    sorting every candidate's full travel, ties to the earlier candidate (the smaller wrist turn)."""

    def __init__(self, choice: GraspChoice, cands: list[Grasp], q0: np.ndarray):
        self.ik = choice.mover.ik
        self.legs: list[list[tuple[np.ndarray, np.ndarray]]] = []  # per candidate: (EE pose to reach, its line's goal)
        for g in cands:
            shift = np.array([*(choice.setup.place_xy - g.center[:2]), 0.0])
            T_pre, T_grasp = choice._grasp_poses(g)
            self.legs.append([(T_pre, T_grasp), (shifted(T_pre, shift), shifted(T_grasp, shift))])
        self.cost = [0.0] * len(cands)  # travel so far (a lower bound until both legs are solved); inf: unreachable
        self.q = [q0] * len(cands)  # the last leg's answer
        self.lines: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in cands]  # (start q, goal EE pose)
        for i in range(len(cands)):
            self._leg(i)

    def _leg(self, i: int) -> None:
        """Solve candidate ``i``'s next leg."""
        T, T_down = self.legs[i][len(self.lines[i])]
        res = self.ik(T, self.q[i])
        if not res.converged:
            self.cost[i] = math.inf
            return
        self.cost[i], self.q[i] = max(self.cost[i], float(np.max(np.abs(res.q - self.q[i])))), res.q
        self.lines[i].append((res.q, T_down))

    def order(self) -> Iterator[int]:
        """The reachable candidates' indices by (travel, index), both legs solved for each one given."""
        pending = [i for i, c in enumerate(self.cost) if c < math.inf]
        while pending:
            i = min(pending, key=lambda i: (self.cost[i], i))  # the others' keys can only grow
            if len(self.lines[i]) < len(self.legs[i]):
                self._leg(i)
                if self.cost[i] == math.inf:
                    pending.remove(i)
                continue
            pending.remove(i)
            yield i


def half_turn(g: Grasp) -> Grasp:
    """The same grasp turned half a turn about its approach axis (fingers swapped)."""
    return Grasp(g.center, g.rotation @ np.diag([1.0, -1.0, -1.0]), g.width)


def shifted(T: np.ndarray, d) -> np.ndarray:
    out = T.copy()
    out[:3, 3] += np.asarray(d, float)
    return out
