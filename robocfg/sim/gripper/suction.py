"""Suction cup: a fixed constraint to the object, made only when the cup touches it.

``on()`` arms the cup; each ``update()`` while armed and empty looks for a movable body in contact
with the suction link (or within ``activation_distance``) and welds it *at the current relative
pose* (no snap). While attached, the constraint's reaction force is read every step; above
``hold_force`` (N) the object lets go (``released_by_load`` is set). ``off()`` releases.
Constraint frames are given relative to the centres of mass, as PyBullet requires.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pybullet as p

from robocfg.config.robot import SuctionGripperConfig
from robocfg.geometry import matrix_to_pose, pose_to_matrix
from robocfg.sim.gripper.base import CLOSED, OPEN, Gripper
from robocfg.sim.gripper.registry import register

CONSTRAINT_FORCE_FACTOR = 10.0  # the weld can push back up to this × hold_force; the check releases first
LOAD_TIME_CONSTANT = 0.02  # s, low-pass of the estimated pull (one-step acceleration spikes are noise)

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World


@register("suction")
class SuctionGripper(Gripper):
    """``on()``, ``off()``, ``is_grasping(body)``, ``attached`` (body id or None)."""

    config: SuctionGripperConfig
    grasps_at_surface = True

    def __init__(self, world: World, arm: ArmHandle):
        super().__init__(world, arm)
        self.link = self.robot.link(self.config.link)
        self.active = False
        self.attached: int | None = None
        self.constraint: int | None = None
        self.released_by_load = False
        self.last_load = 0.0  # N, filtered pull on the cup (positive: pulling the object off)
        self._v_prev: np.ndarray | None = None
        self._mass = 0.0

    def on(self) -> None:
        self.active = True
        self.released_by_load = False

    def off(self) -> None:
        self.active = False
        self._detach()

    open = off
    close = on

    def reset(self, fraction: float = 1.0) -> None:
        """Back to the initial state (suction off, nothing attached); ``fraction`` is ignored."""
        self.off()
        self.released_by_load = False

    def fraction(self) -> float:
        """0.0 (closed) while suction is on, 1.0 (open) when off: a cup has no travel in between."""
        return 0.0 if self.active else 1.0

    def state(self) -> float:
        """−1.0 (closed) while suction is on, 1.0 (open) when off."""
        return CLOSED if self.active else OPEN

    def is_grasping(self, body: int | str) -> bool:
        return self.attached is not None and self.attached == self._body_id(body)

    def busy(self) -> bool:
        """True while suction is on: each step looks for a body to hold, or checks the one held."""
        return self.active

    def update(self) -> None:
        if not self.active:
            return
        if self.attached is None:
            target = self._candidate()
            if target is not None:
                self._attach(target)
            return
        dt = self.world.dt
        alpha = min(1.0, dt / LOAD_TIME_CONSTANT)
        self.last_load += alpha * (self._pull(dt) - self.last_load)
        if self.last_load > self.config.hold_force:
            self._detach()
            self.released_by_load = True
            self.active = False

    def _pull(self, dt: float) -> float:
        """Force (N) the weld exerts on the object, along the direction from the object into the cup."""
        bid, c = self.attached, self.client
        v = np.asarray(p.getBaseVelocity(bid, physicsClientId=c)[0])
        a = np.zeros(3) if self._v_prev is None else (v - self._v_prev) / dt
        self._v_prev = v
        g = np.asarray(self.world.task.config.sim.gravity, dtype=float)
        force = self._mass * (a - g)
        for pt in p.getContactPoints(bodyA=bid, physicsClientId=c):
            if pt[1] == bid:  # normal on B points from B to A: the force on A is +normalForce·n
                force -= pt[9] * np.asarray(pt[7])
            else:
                force += pt[9] * np.asarray(pt[7])
        into_cup = -self.robot.link_pose(self.config.link)[:3, 2]
        return float(force @ into_cup)

    def _candidate(self) -> int | None:
        rid = self.robot.body_id
        best: tuple[float, int] | None = None
        for c in p.getContactPoints(bodyA=rid, linkIndexA=self.link, physicsClientId=self.client):
            if c[2] != rid and self._movable(c[2]):
                best = min(best or (c[8], c[2]), (c[8], c[2]))
        if best is None and self.config.activation_distance > 0:
            for bid in self.world.bodies.values():
                if bid == rid or not self._movable(bid):
                    continue
                pts = p.getClosestPoints(rid, bid, self.config.activation_distance, self.link, physicsClientId=self.client)
                for c in pts:
                    best = min(best or (c[8], bid), (c[8], bid))
        return None if best is None else best[1]

    def _movable(self, bid: int) -> bool:
        return p.getDynamicsInfo(bid, -1, physicsClientId=self.client)[0] > 0

    def _com(self, bid: int, link: int) -> np.ndarray:
        if link == -1:
            pos, orn = p.getBasePositionAndOrientation(bid, physicsClientId=self.client)
        else:
            s = p.getLinkState(bid, link, computeForwardKinematics=True, physicsClientId=self.client)
            pos, orn = s[0], s[1]
        return pose_to_matrix(pos, orn)

    def _attach(self, bid: int) -> None:
        T = np.linalg.inv(self._com(self.robot.body_id, self.link)) @ self._com(bid, -1)
        pos, quat = matrix_to_pose(T)
        self.constraint = p.createConstraint(
            self.robot.body_id, self.link, bid, -1, p.JOINT_FIXED, [0, 0, 0],
            parentFramePosition=pos.tolist(), childFramePosition=[0, 0, 0],
            parentFrameOrientation=quat.tolist(), childFrameOrientation=[0, 0, 0, 1],
            physicsClientId=self.client)
        p.changeConstraint(self.constraint, maxForce=CONSTRAINT_FORCE_FACTOR * self.config.hold_force,
                           physicsClientId=self.client)
        # The weld replaces the cup-object contact: the two fighting would corrupt both forces.
        p.setCollisionFilterPair(self.robot.body_id, bid, self.link, -1, 0, physicsClientId=self.client)
        self.attached = bid
        self._mass = p.getDynamicsInfo(bid, -1, physicsClientId=self.client)[0]
        self._v_prev = None
        self.last_load = 0.0

    def _detach(self) -> None:
        if self.constraint is not None:
            p.removeConstraint(self.constraint, physicsClientId=self.client)
            p.setCollisionFilterPair(self.robot.body_id, self.attached, self.link, -1, 1, physicsClientId=self.client)
        self.constraint, self.attached, self.last_load = None, None, 0.0
