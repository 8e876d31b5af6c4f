"""The collision-avoidance constraint of the reactive controller's QP.

Which geometry pairs are watched: every moving robot geometry against every environment shape
(except a non-obstacle shape such as the pedestal or table that the robot already touches at its
posture: it stands on it), and, with self collision on, robot pairs under different arm joints that
are more than ``2·margin`` apart at the posture (adjacent hulls overlap). Each step, every pair
inside ``trigger`` (``self_trigger`` for self pairs) gives one half-space row of a velocity damper
``n·(J_B − J_A)·Δq ≥ −approach_gain·dt·(d − margin) (− n·v_obstacle·dt)``, ``n`` the unit normal
from the robot geometry A towards B and ``d`` their coal distance (m). Frames: world; Jacobians
over the arm joints (rad).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from robocfg.collision.distances import DistanceField
from robocfg.collision.shapes import EnvShape, robot_geometry_ids, set_environment_pose
from robocfg.motion.reactive.escape import Blocking

if TYPE_CHECKING:
    import pinocchio as pin
    import placo

    from robocfg.motion.reactive.controller import ArmSpec, ReactiveSettings


class CollisionRows:
    """The watched pairs of ``geom`` (a pinocchio ``GeometryModel`` holding the robot's hulls and
    the environment shapes ``env_ids``) and the rows they put into the QP; see the module docstring.

    ``set_q`` poses the arm (arm-joint order, rad) and updates the robot's kinematics; ``q_index``
    and ``v_index`` are the arm joints' offsets in the robot's configuration and velocity vectors.
    """

    def __init__(self, robot: placo.RobotWrapper, geom: pin.GeometryModel, arm: ArmSpec, env: dict[str, EnvShape], env_ids: dict[str, int],
                 settings: ReactiveSettings, set_q: Callable[[np.ndarray], None], q_index: np.ndarray,
                 v_index: np.ndarray):
        self.robot, self.geom, self.arm, self.s = robot, geom, arm, settings
        self.env, self.env_ids = env, env_ids
        self._set_q, self._q_index, self._v_index = set_q, q_index, v_index
        self._jacobians: dict[int, np.ndarray] = {}
        self._env_velocity: dict[int, np.ndarray] = {}
        self._select_pairs()

    def _select_pairs(self) -> None:
        """Robot–environment pairs for every moving robot geometry (except pairs with a non-obstacle
        shape such as the pedestal or table that are already within the margin at the posture: the
        robot stands on it); self pairs for geometries more than ``2·margin`` apart at the posture
        (adjacent hulls overlap and are skipped)."""
        import pinocchio as pin

        g = self.geom
        g.removeAllCollisionPairs()
        base_joints = {0, 1}  # universe and placo's floating base: geometry there cannot move
        robot_ids = robot_geometry_ids(g, base_joints)
        all_robot = robot_geometry_ids(g, set())
        for rid in robot_ids:
            for eid in self.env_ids.values():
                g.addCollisionPair(pin.CollisionPair(rid, eid))
        if self.s.self_collision:
            anc = self._arm_ancestors()
            for a in all_robot:
                for b in all_robot:
                    ja, jb = anc[g.geometryObjects[a].parentJoint], anc[g.geometryObjects[b].parentJoint]
                    if a < b and ja != jb:  # same arm-joint ancestor: rigid to each other in the QP
                        g.addCollisionPair(pin.CollisionPair(a, b))
        self._set_q(self.arm.posture)
        field = DistanceField(self.robot.model, g)
        field.update(np.asarray(self.robot.state.q))
        found, _ = field.query(np.inf)
        keep, self.support_pairs = [], []
        for d in found:
            na, nb = g.geometryObjects[d.a].name, g.geometryObjects[d.b].name
            if nb.startswith("env:"):
                if not self.env[nb[4:]].obstacle and d.distance < self.s.margin:
                    self.support_pairs.append((na, nb[4:]))  # robot resting on/next to it: not avoided
                    continue
            elif d.distance <= 2 * self.s.margin:
                continue  # self pair already close at the posture (adjacent hulls overlap)
            keep.append((d.a, d.b))
        g.removeAllCollisionPairs()
        for a, b in keep:
            g.addCollisionPair(pin.CollisionPair(a, b))
        self.pairs = [(p.first, p.second) for p in g.collisionPairs]
        self._names = [o.name for o in g.geometryObjects]
        self._env_pair = np.array([self._names[b].startswith("env:") for _, b in self.pairs], dtype=bool)
        self._obstacle_pair = np.array([self._env_pair[k] and self.env[self._names[b][4:]].obstacle
                                        for k, (_, b) in enumerate(self.pairs)], dtype=bool)
        self.field = DistanceField(self.robot.model, g)
        self._cutoff = np.where(self._env_pair, self.s.trigger, self.s.self_trigger)

    def _arm_ancestors(self) -> list[int]:
        """For every pinocchio joint, the nearest arm joint at or above it (0 for none): geometry
        below the same arm joint moves rigidly in the QP (gripper joints are held fixed)."""
        model = self.robot.model
        arm_ids = {model.getJointId(n) for n in self.arm.joint_names}
        out = []
        for j in range(model.njoints):
            k = j
            while k > 0 and k not in arm_ids:
                k = model.parents[k]
            out.append(k)
        return out

    def set_obstacle_pose(self, name: str, pose: np.ndarray, velocity: np.ndarray | None = None) -> None:
        """Move environment shape ``name`` to ``pose`` (4×4, world); ``velocity`` (m/s, world) is its
        linear velocity, used so the robot keeps the margin from an approaching obstacle."""
        self.env[name].pose = np.asarray(pose, float)
        set_environment_pose(self.geom, self.env_ids[name], pose)
        self._env_velocity[self.env_ids[name]] = np.zeros(3) if velocity is None else np.asarray(velocity, float)[:3]

    def distances(self) -> list[tuple[str, str, float]]:
        """(robot geometry, environment/robot geometry, distance m) for every pair, at the model state."""
        self.field.update(np.asarray(self.robot.state.q))
        found, _ = self.field.query(np.inf)
        return [(self._names[d.a], self._names[d.b], d.distance) for d in found]

    def fill(self, A: np.ndarray, b: np.ndarray, q: np.ndarray) -> tuple[list[Blocking], float]:
        """Fill the half-spaces ``A·q_full ≤ b`` (one row per pair inside its trigger, the rest
        inactive) at the robot's current state, linearised at the arm command ``q`` (rad); return
        the robot–environment pairs inside the trigger distance and the smallest robot–obstacle
        distance (m)."""
        A[:] = 0.0
        b[:] = 1.0
        q_full = np.asarray(self.robot.state.q)
        self.field.update(q_full)
        found, dist = self.field.query(self._cutoff)
        clearance = float(dist[self._obstacle_pair].min()) if self._obstacle_pair.any() else float("inf")
        near: list[Blocking] = []
        xi = self.s.approach_gain * self.s.dt
        self._jacobians = {}

        row = 0
        for d in found:
            env = self._env_pair[d.pair]
            if env:
                near.append(Blocking(d.distance, -d.normal))
            if d.distance >= (self.s.trigger if env else self.s.self_trigger) or row >= A.shape[0]:
                continue
            # d' = n·(v_B − v_A) ≥ −ξ·(d − margin): a velocity damper, n from A (robot) towards B
            ja, jb = self.geom.geometryObjects[d.a].parentJoint, self.geom.geometryObjects[d.b].parentJoint
            row_v = -self.normal_row(ja, d.point_a, d.normal, q_full)
            if jb > 1:
                row_v = row_v + self.normal_row(jb, d.point_b, d.normal, q_full)
            A[row, self._q_index] = -row_v
            b[row] = xi * (d.distance - self.s.margin) + A[row, self._q_index] @ q
            v_b = self._env_velocity.get(d.b)
            if v_b is not None:  # a moving obstacle: its own approach speed counts against the margin
                b[row] += float(d.normal @ v_b) * self.s.dt
            row += 1
        return near, clearance

    def normal_row(self, joint: int, p: np.ndarray, n: np.ndarray, q_full: np.ndarray) -> np.ndarray:
        """``n · J_p`` over the arm joints: the speed along ``n`` of the world point ``p`` fixed to
        pinocchio joint ``joint``'s body, per unit arm-joint velocity (Jacobians cached per
        :meth:`fill`; call :meth:`forget_jacobians` before using it at another state)."""
        import pinocchio as pin

        J = self._jacobians.get(joint)
        if J is None:
            model, data = self.field.model, self.field.data
            if not self._jacobians:
                pin.computeJointJacobians(model, data, q_full)
            J = self._jacobians[joint] = pin.getJointJacobian(model, data, joint, pin.ReferenceFrame.WORLD)[:, self._v_index]
        # v_p = v_O + ω × p, so n·v_p = n·v_O + (p × n)·ω
        pxn = np.array([p[1] * n[2] - p[2] * n[1], p[2] * n[0] - p[0] * n[2], p[0] * n[1] - p[1] * n[0]])
        return n @ J[:3] + pxn @ J[3:]

    def forget_jacobians(self) -> None:
        """Drop the Jacobians cached by the last :meth:`fill`."""
        self._jacobians = {}
