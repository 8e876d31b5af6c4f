"""Enforce URDF ``<mimic>`` tags with PyBullet gear constraints.

For each follower ``q_f = multiplier · q_l + offset``: switch the follower's default velocity motor
off (``VELOCITY_CONTROL``, force 0), then add a ``JOINT_GEAR`` constraint from leader (A) to
follower (B). PyBullet's gear row enforces ``q_A + gearRatio · q_B = relativePositionTarget``,
so ``gearRatio = −1 / multiplier`` and ``relativePositionTarget = −offset / multiplier``.
``erp = 1`` makes the row correct position error (the default 0 is velocity-only and drifts).
Measured on the Robotiq 2F-85: ≤ 0.004 rad error while grasping (shared/field-notes.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet as p

from robocfg.sim.robot import RobotHandle

DEFAULT_MAX_FORCE = 1000.0  # N·m or N: far above any finger load, the solver caps it anyway


@dataclass(frozen=True)
class MimicPair:
    leader: str
    follower: str
    multiplier: float
    offset: float
    constraint_id: int


class MimicGears:
    """The gear constraints of one robot; ``skipped`` explains mimic tags not enforced."""

    def __init__(self, robot: RobotHandle, max_force: float = DEFAULT_MAX_FORCE):
        self.robot = robot
        self.pairs: list[MimicPair] = []
        self.skipped: list[str] = []
        client = robot.client
        for j in robot.checked.urdf.joints.values():
            m = j.mimic
            if m is None:
                continue
            why = self._unsupported(j.name, m.joint, m.multiplier)
            if why:
                self.skipped.append(f"mimic tag of joint {j.name!r} not enforced: {why}")
                continue
            robot.release_joints([j.name])
            cid = p.createConstraint(robot.body_id, robot.joint_index[m.joint], robot.body_id,
                                     robot.joint_index[j.name], p.JOINT_GEAR, [1, 0, 0], [0, 0, 0],
                                     [0, 0, 0], physicsClientId=client)
            p.changeConstraint(cid, gearRatio=-1.0 / m.multiplier, erp=1.0, maxForce=max_force,
                               relativePositionTarget=-m.offset / m.multiplier, physicsClientId=client)
            self.pairs.append(MimicPair(m.joint, j.name, m.multiplier, m.offset, cid))

    def _unsupported(self, follower: str, leader: str, multiplier: float) -> str:
        r = self.robot
        if leader not in r.joint_index:
            return f"leader joint {leader!r} does not exist"
        for n in (leader, follower):
            if r.joint_types[n] not in (p.JOINT_REVOLUTE, p.JOINT_PRISMATIC):
                return f"joint {n!r} is not movable"
        if abs(multiplier) < 1e-9:
            return "multiplier is 0"
        if r.checked.urdf.joints[leader].mimic is not None:
            return f"leader {leader!r} is itself a mimic follower (chains are not supported)"
        return ""

    @property
    def followers(self) -> list[str]:
        return [m.follower for m in self.pairs]

    def expected(self, name: str, q_leader: float) -> float:
        m = next(m for m in self.pairs if m.follower == name)
        return m.multiplier * q_leader + m.offset

    def sync(self) -> None:
        """Teleport every follower to where its leader says (after a reset of the leader)."""
        for m in self.pairs:
            q = self.robot.joint_positions([m.leader])[0]
            self.robot.reset_joints([m.follower], [m.multiplier * q + m.offset], hold=False)

    def errors(self) -> np.ndarray:
        """|q_follower − (multiplier · q_leader + offset)| per pair (rad or m)."""
        if not self.pairs:
            return np.zeros(0)
        names = [n for m in self.pairs for n in (m.leader, m.follower)]
        q = self.robot.joint_positions(names).reshape(-1, 2)
        mult = np.array([m.multiplier for m in self.pairs])
        off = np.array([m.offset for m in self.pairs])
        return np.abs(q[:, 1] - (mult * q[:, 0] + off))

    def max_error(self) -> float:
        e = self.errors()
        return float(e.max()) if len(e) else 0.0
