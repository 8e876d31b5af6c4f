"""Parallel-jaw gripper: driven (leader) joints in position control, mimic followers geared.

Width is *measured*: the closest distance between the two finger links' collision shapes
(PyBullet ``getClosestPoints``, convex hulls), never the command echoed back. ``set_width`` inverts
the pad gap computed by URDF forward kinematics over the closed→open travel
(``robocfg.assets.fingers.width_curve``), so linkages whose width is not linear in the joint
(Robotiq, xArm) get the width asked for; without finger geometry it falls back to a linear map
between ``closed`` (``min_width``) and ``open`` (``max_width``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pybullet as p

from robocfg.config.robot import ParallelGripperConfig
from robocfg.sim.gripper.base import CLOSED, OPEN, Gripper
from robocfg.sim.gripper.registry import register
from robocfg.sim.robot import Drive

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.config.robot import ArmConfig
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World


@register("parallel")
class ParallelGripper(Gripper):
    """``open()``, ``close()``, ``set_width(m)``, ``width()`` (measured), ``state()``, ``is_grasping(body)``.

    ``rate`` (fraction of the closed→open travel per second) makes targets move smoothly, like the
    seed's "+0.1 per step"; ``None`` jumps the target at once (the drive's ``max_velocity`` still caps
    the joint speed).
    """

    config: ParallelGripperConfig

    def __init__(self, world: World, arm: ArmHandle, rate: float | None = None):
        super().__init__(world, arm)
        cfg: ParallelGripperConfig = self.config
        self.joints = self.robot.checked.gripper_joints(arm.config)
        self.q_open = np.asarray(cfg.open, dtype=float)
        self.q_closed = np.asarray(cfg.closed, dtype=float)
        self.fingers = [self.robot.link(n) for n in cfg.finger_links]
        self.rate = rate
        self.force = cfg.max_force
        self._joint_indices = self.robot.joint_indices(self.joints)
        # (closed position, open − closed) per driven joint as Python floats, for fraction(); None: numpy's mean
        terms = [(float(c), float(o - c)) for c, o in zip(self.q_closed, self.q_open, strict=True)]
        self._fraction_terms = terms if len(terms) in (1, 2) and all(span != 0.0 for _, span in terms) else None
        gains = self.robot.config.drives.arm
        self._gains = (gains.stiffness, gains.damping)
        # A soft pad pressed on an object touches it over a patch, not at a point: uniform pressure over a
        # disc of radius a resists turning with up to (2/3)·μ·a·N (N·m). Bullet multiplies a body's
        # spinning friction by the other body's lateral friction, so the object's μ completes the product.
        spinning = 2.0 / 3.0 * cfg.lateral_friction * cfg.pad_patch_radius
        for f in self.fingers:
            p.changeDynamics(self.robot.body_id, f, lateralFriction=cfg.lateral_friction, spinningFriction=spinning,
                             physicsClientId=self.client)
        self._curve: tuple[np.ndarray, np.ndarray] | None = None  # (fractions, gaps), on first set_width
        self._curve_done = False
        self._goal = 1.0  # commanded opening fraction (0 closed, 1 open)
        self._cmd = 1.0  # fraction currently sent to the drives (rate-limited towards _goal)
        self._send()

    # ---- commands (non-blocking) -----------------------------------------------------------
    def open(self) -> None:
        """Open (non-blocking). Opening from a closing or closed command is a release: first the
        fingers' contacts with every body they touch are rebuilt from the geometry as it is
        (:meth:`robocfg.sim.queries.SceneQueries.refresh_contacts`): PyBullet keeps contact points
        across steps, and one kept from the carry whose normal has turned round (a fingertip corner
        in the object's face) drags the object with an opening finger (measured on the Panda
        shelf: 10 mm sideways) or holds the fingers shut. Done here, where the command reaches the
        drives, so a dataset replay (whose command gate sends the recorded open at the same
        physics step) rebuilds them at the same step."""
        if self._goal < 1.0:
            for body in self._touched():
                self.world.refresh_contacts(self.robot.body_id, body, self.fingers)
        self.set_fraction(1.0)

    def _touched(self) -> list[int]:
        """Bodies (ids, ascending) other than the robot that a finger link touches (a contact point
        of the last step at distance ≤ 0)."""
        me, c = self.robot.body_id, self.client
        return sorted({int(k[2]) for f in self.fingers for k in p.getContactPoints(me, linkIndexA=f, physicsClientId=c)
                       if k[2] != me and k[8] <= 0.0})

    def close(self) -> None:
        self.set_fraction(0.0)

    def set_width(self, width: float) -> None:
        """Command a finger gap (m), clipped to what the fingers can do (the pad-gap curve, else [min_width, max_width])."""
        cfg = self.config
        if not self._curve_done:
            self._curve, self._curve_done = _width_curve(self.robot.checked, self.arm.config), True
        if self._curve is not None:
            s, gaps = self._curve
            order = np.argsort(gaps)
            self.set_fraction(float(np.interp(width, gaps[order], s[order])))
            return
        self.set_fraction((width - cfg.min_width) / (cfg.max_width - cfg.min_width))

    def set_fraction(self, s: float) -> None:
        """Command an opening fraction: 0 = ``closed`` joint positions, 1 = ``open``."""
        s = float(s)
        self._goal = s if 0.0 <= s <= 1.0 else float(np.clip(s, 0.0, 1.0))  # (np.clip keeps an in-range value as it is)
        if self.rate is None:
            self._cmd = self._goal
            self._send()

    def set_force(self, force: float) -> None:
        """Force (N) or torque (N·m) cap of each driven joint."""
        self.force = float(force)
        self._send()

    def reset(self, fraction: float = 1.0) -> None:
        """Teleport the fingers to an opening fraction (followers included) and hold there."""
        self._goal = self._cmd = float(np.clip(fraction, 0.0, 1.0))
        self.robot.reset_joints(self.joints, self._q(self._cmd), hold=False)
        if self.robot.mimic is not None:
            self.robot.mimic.sync()
        self._send()

    def busy(self) -> bool:
        """True while a rate-limited target is still moving towards the commanded opening."""
        return bool(self._cmd != self._goal)

    def update(self) -> None:
        if self._cmd == self._goal:
            return
        step = self.rate * self.world.dt if self.rate is not None else 1.0
        self._cmd = self._goal if abs(self._goal - self._cmd) <= step else self._cmd + np.sign(self._goal - self._cmd) * step
        self._send()

    def _q(self, s: float) -> np.ndarray:
        return self.q_closed + s * (self.q_open - self.q_closed)

    def _send(self) -> None:
        kp, kd = self._gains
        s = self._cmd
        # _q(s) in Python floats where fraction() has the terms: q_closed + s·(q_open − q_closed), per joint
        targets = self._q(s).tolist() if self._fraction_terms is None else [c + s * span for c, span in self._fraction_terms]
        for n, q in zip(self.joints, targets, strict=True):
            self.robot.set_drive(n, Drive(float(q), kp, kd, self.force, max_velocity=self.config.max_velocity))

    # ---- measurements ------------------------------------------------------------------------
    @property
    def target_fraction(self) -> float:
        return self._goal

    def width(self) -> float:
        """Measured finger gap (m): closest distance between the finger links' collision shapes (≥ 0)."""
        r = self.robot
        pts = p.getClosestPoints(r.body_id, r.body_id, 1.0, self.fingers[0], self.fingers[1], physicsClientId=self.client)
        if not pts:  # fingers without collision shapes: fall back to the distance between their frames
            a, b = (r.link_pose(n)[:3, 3] for n in self.config.finger_links)
            return float(np.linalg.norm(a - b))
        return max(0.0, float(min(c[8] for c in pts)))

    def fraction(self) -> float:
        """Measured opening fraction of the driven joints (0 closed, 1 open), averaged. One or two
        driven joints (every gripper shipped) in Python floats: the same IEEE operations as the
        arrays' (a mean of two is their sum halved in any order)."""
        if self._fraction_terms is None:
            return float(np.mean((self.robot.joint_positions(self.joints) - self.q_closed) / (self.q_open - self.q_closed)))
        states = p.getJointStates(self.robot.body_id, self._joint_indices, physicsClientId=self.client)
        return self.fraction_at([s[0] for s in states])

    def fraction_at(self, q: list[float]) -> float:
        """The opening :meth:`fraction` measures when the driven joints (``gripper_joints``, in
        order) stand at ``q`` (rad or m): the same operations on the same values."""
        if self._fraction_terms is None:
            return float(np.mean((np.array(q, dtype=float) - self.q_closed) / (self.q_open - self.q_closed)))
        if len(q) == 1:
            ((lo, span),) = self._fraction_terms
            return (q[0] - lo) / span  # the mean of one value is itself
        qa, qb = q
        (la, sa), (lb, sb) = self._fraction_terms
        return ((qa - la) / sa + (qb - lb) / sb) / 2

    def state(self) -> float:
        """1.0 (open) when the measured fraction exceeds ``state_threshold``, else −1.0 (closed)."""
        return OPEN if self.fraction() > self.config.state_threshold else CLOSED

    def finger_contacts(self, body: int | str) -> list[int]:
        """Number of contact points between each finger link and ``body``."""
        bid = self._body_id(body)
        return [len(p.getContactPoints(self.robot.body_id, bid, f, physicsClientId=self.client)) for f in self.fingers]

    def refresh_contacts(self, body: int | str, touching_only: bool = False) -> bool:
        bid = self._body_id(body)
        if touching_only and not self.world.touching(self.robot.body_id, bid, self.fingers):
            return False
        self.world.refresh_contacts(self.robot.body_id, bid, self.fingers)
        return True

    def is_grasping(self, body: int | str) -> bool:
        """Both finger links touch ``body`` (a body id or a world body name): each has a contact
        point of the last step with it (one query of the robot's contacts with the body)."""
        pts = p.getContactPoints(self.robot.body_id, self._body_id(body), physicsClientId=self.client)
        links = {c[3] for c in pts}  # the robot's link of each point (PyBullet puts the asked body A first)
        return all(f in links for f in self.fingers)


def _width_curve(checked: CheckedRobot, arm_cfg: ArmConfig) -> tuple[np.ndarray, np.ndarray] | None:
    """Pad gap vs opening fraction from the URDF, or None when it cannot be computed or is not
    monotonic (then ``set_width`` stays linear)."""
    curve = checked.pad_gap_curve(arm_cfg)
    if curve is None:
        return None
    s, gaps = curve
    d = np.diff(gaps)
    if not (np.all(d >= -1e-6) or np.all(d <= 1e-6)) or np.ptp(gaps) < 1e-4:
        return None
    return s, gaps
