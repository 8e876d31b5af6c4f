"""``placo``: placo's KinematicsSolver (a QP per step) with joint limits.

placo's ``RobotWrapper`` always adds a floating base: it is placed at the mount pose and masked,
as are every non-arm joint (set to the model's locked values). The TCP is added to the URDF given
to placo as a fixed link, so its frame task acts on the same point as the other backends. Each
``solve(True)`` is one QP step followed by integration; steps repeat until the tolerance, a stall,
or the time budget.

Self-collision avoidance (``self_collision=True``, the default when the model knows its robot
config): the URDF's collision geometry is added as convex hulls built from the mesh vertices
(the reactive controller's helpers; loading the meshes through placo takes seconds). Pairs are
every two geometries under different arm joints that are more than ``2·margin`` apart at home
(adjacent hulls overlap there). Each descent runs without the constraint, so a collision-free
answer costs what pure IK costs (plus one collision check, ≈ 0.04 ms for the Panda's 40 pairs).
When its answer penetrates, a *repair* descent starts from that answer with placo's
``AvoidSelfCollisions`` constraint (linearised ``d + J·Δq ≥ margin`` for pairs closer than
``trigger``, hard priority; at most ``repair_iter`` steps, ≈ 0.3 ms each): it moves along the
self-motion out of collision while the frame task holds the pose. If that fails (the branch is
colliding), the search restarts from a random configuration. An answer is only accepted when no
pair penetrates; if none is found in the budget the result is ``converged=False`` (best q kept,
collision-free ones ranked first). Pairs left out (close at home) are not checked.

placo is imported when the solver is built.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from time import perf_counter
from typing import TYPE_CHECKING, Any

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
    from robocfg.collision import DistanceField
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel

PLACO_TCP = "robocfg_tcp"


def _urdf_with_tcp(km: KinematicModel) -> str:
    """The model's URDF text (continuous joints revolute, no geometry) plus a fixed ``robocfg_tcp`` link."""
    from robocfg.kinematics.model import TCP_FRAME, _urdf_xml_without_continuous

    xml, _ = _urdf_xml_without_continuous(str(km.urdf_path))
    root = ET.fromstring(xml)
    for link in root.iter("link"):  # kinematics only: loading meshes would take seconds
        for tag in ("visual", "collision"):
            for el in link.findall(tag):
                link.remove(el)
    ee = km.model.frames[km.frame_id("ee")]
    tcp = km.model.frames[km.frame_id(TCP_FRAME)]
    ee_T_tcp = ee.placement.actInv(tcp.placement)
    ET.SubElement(root, "link", name=PLACO_TCP)
    j = ET.SubElement(root, "joint", name=PLACO_TCP + "_joint", type="fixed")
    ET.SubElement(j, "parent", link=km.ee_link)
    ET.SubElement(j, "child", link=PLACO_TCP)
    xyz = " ".join(repr(float(v)) for v in ee_T_tcp.translation)
    import pinocchio as pin

    rpy = " ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(ee_T_tcp.rotation))
    ET.SubElement(j, "origin", xyz=xyz, rpy=rpy)
    return ET.tostring(root, encoding="unicode")


@register("placo")
class PlacoSolver:
    """placo KinematicsSolver with a frame task (or a position task), joint limits and (optionally)
    self-collision avoidance. ``margin``/``trigger`` in metres."""

    name = "placo"
    clock = staticmethod(perf_counter)  # what the time budget is measured with (thread_time: CPU)

    def __init__(self, model: KinematicModel, tol_pos: float = 1e-5, tol_rot: float = 1e-5,
                 max_iter: int = 100, stall_ratio: float = 0.9, stall_n: int = 5,
                 self_collision: bool = True, margin: float = 0.02, trigger: float = 0.10,
                 repair_iter: int = 20, max_total_iter: int | None = None):
        import placo

        self.km = model
        self.max_total_iter = max_total_iter  # cap over all restarts, repairs included (see IKSolver)
        self.tol_pos, self.tol_rot = tol_pos, tol_rot
        self.max_iter, self.stall_ratio, self.stall_n = max_iter, stall_ratio, stall_n
        self.repair_iter = repair_iter  # QP steps of a repair descent (each ≈ 0.3 ms: distances of every pair)
        self.robot = placo.RobotWrapper(str(model.urdf_path), placo.Flags.ignore_collisions, _urdf_with_tcp(model))
        for name, value in model.locked.items():
            self.robot.set_joint(name, value)
        self.robot.set_T_world_fbase(model.base_pose)
        self.robot.update_kinematics()
        self.solver = placo.KinematicsSolver(self.robot)
        self.solver.mask_fbase(True)
        for name in model.locked:
            self.solver.mask_dof(name)
        self.solver.enable_joint_limits(True)
        self.solver.enable_velocity_limits(False)
        self.solver.dt = 1.0
        self._task: Any = None  # placo's frame or position task of the current query
        self.field: DistanceField | None = None  # DistanceField over the self-collision pairs (None: avoidance off)
        self.pair_names: list[tuple[str, str]] = []
        self._avoid: Any = None  # placo's constraint while it is in the QP
        if self_collision and model.robot is not None:
            self._setup_self_collision(margin, trigger)

    def _setup_self_collision(self, margin: float, trigger: float) -> None:
        """Add the robot's collision hulls (and the other arms', locked) and select the self pairs."""
        import pinocchio as pin

        from robocfg.collision import DistanceField, robot_geometry
        from robocfg.collision.shapes import add_robot_geometry, robot_geometry_ids

        if self.km.robot is None:  # a model built from a bare URDF: no collision geometry known
            return
        geoms, _missing = robot_geometry(self.km.robot)  # links with unreadable meshes are not avoided
        g = self.robot.collision_model
        add_robot_geometry(g, self.robot.model, geoms)
        model = self.robot.model
        arm_ids = {model.getJointId(n) for n in self.km.joint_names}
        anc = []  # nearest arm joint at or above each joint: geometry under the same one is rigid
        for j in range(model.njoints):
            while j > 0 and j not in arm_ids:
                j = model.parents[j]
            anc.append(j)
        ids = robot_geometry_ids(g, set())
        g.removeAllCollisionPairs()
        for i, a in enumerate(ids):
            for b in ids[i + 1:]:
                if anc[g.geometryObjects[a].parentJoint] != anc[g.geometryObjects[b].parentJoint]:
                    g.addCollisionPair(pin.CollisionPair(a, b))
        self._set_q(self.km.home)
        field = DistanceField(model, g)
        field.update(np.asarray(self.robot.state.q))
        _, dist = field.query(0.0)
        keep = [(p.first, p.second) for p, d in zip(g.collisionPairs, dist, strict=True) if d > 2 * margin]
        g.removeAllCollisionPairs()
        for a, b in keep:
            g.addCollisionPair(pin.CollisionPair(a, b))
        if not keep:
            return
        self.pair_names = [(g.geometryObjects[a].name, g.geometryObjects[b].name) for a, b in keep]
        self.field = DistanceField(model, g)
        self.margin, self.trigger = margin, trigger

    def _set_avoid(self, on: bool) -> None:
        """Add or remove placo's self-collision constraint (placo frees a removed constraint, so it is
        created anew each time)."""
        if self.field is None or on == (self._avoid is not None):
            return
        if on:
            self._avoid = self.solver.add_avoid_self_collisions_constraint()
            self._avoid.configure("self_collisions", "hard", 1.0)
            self._avoid.self_collisions_margin = self.margin
            self._avoid.self_collisions_trigger = self.trigger
        else:
            self.solver.remove_constraint(self._avoid)
            self._avoid = None

    def min_distance(self, q: np.ndarray) -> float:
        """Smallest distance (m, negative: penetration) over the self-collision pairs at arm
        values ``q`` (inf when avoidance is off)."""
        if self.field is None:
            return math.inf
        self._set_q(q)
        self.field.update(np.asarray(self.robot.state.q))
        _, dist = self.field.query(0.0)
        return float(dist.min()) if len(dist) else math.inf

    def collides(self, q: np.ndarray) -> bool:
        """True if some self-collision pair penetrates at arm values ``q`` (False when avoidance is off)."""
        import pinocchio as pin

        if self.field is None:
            return False
        self._set_q(q)
        f = self.field
        return bool(pin.computeCollisions(f.model, f.data, f.geom, f.gdata, np.asarray(self.robot.state.q), True))

    def _frame(self, frame: str) -> str:
        return PLACO_TCP if frame == "tcp" else self.km.frame_name(frame)

    def solve(self, target: np.ndarray, seed_q: np.ndarray, frame: str = "tcp",
              time_budget: float = 0.02, position_only: bool = False,
              rng: np.random.Generator | None = None) -> IKResult:

        t0 = perf_counter()
        km = self.km
        T, q0, fid, Mt = prepare(km, target, seed_q, frame)
        if self._task is not None:
            self.solver.remove_task(self._task)
        name = self._frame(frame)
        if position_only:
            self._task = self.solver.add_position_task(name, T[:3, 3].copy())
        else:
            self._task = self.solver.add_frame_task(name, T.copy())
        self._task.configure("target", "soft", 1.0)

        def descend(q: np.ndarray, deadline: float, cap: int | None):
            self._set_avoid(False)
            ok, it, s, q_end = self._descend(q, Mt, fid, position_only, deadline,
                                             self.max_iter if cap is None else min(self.max_iter, cap))
            if not ok or self.field is None or not self.collides(q_end):
                return ok, it, s, q_end
            # the answer penetrates: from it, move along the self-motion out of collision, keeping the pose
            ok2, it2 = False, 0
            repair = self.repair_iter if cap is None else min(self.repair_iter, cap - it)
            if repair > 0:
                self._set_avoid(True)
                ok2, it2, s2, q2 = self._descend(q_end, Mt, fid, position_only, deadline, repair)
            if ok2:
                return ok2, it + it2, s2, q2
            return False, it + it2, s + 1.0, q_end  # penalised: any collision-free q ranks first

        self._set_avoid(False)
        best_q, iters, restarts = search(km, descend, q0, self.clock() + time_budget, rng, self.clock,
                                         self.max_total_iter)
        self._set_avoid(False)
        res = finish(km, self.name, nearest_equivalent(km, best_q, q0), Mt, fid, position_only, self.tol_pos, self.tol_rot,
                     t0, iters, restarts)
        if res.converged and self.collides(res.q):
            res.converged = False
        return res

    def _set_q(self, q: np.ndarray) -> None:
        for name, v in zip(self.km.joint_names, q.tolist(), strict=True):
            self.robot.set_joint(name, v)
        self.robot.update_kinematics()

    def _get_q(self) -> np.ndarray:
        return np.array([self.robot.get_joint(n) for n in self.km.joint_names])

    def _descend(self, q, Mt, fid, position_only, deadline, max_iter=None):
        import pinocchio as pin

        km = self.km
        self._set_q(q)
        track = Descent(q, self.tol_pos, self.tol_rot, self.stall_ratio, self.stall_n)
        max_iter = max_iter or self.max_iter
        for it in range(1, max_iter + 1):
            qc = km.lower + np.clip(self._get_q() - km.lower, 0.0, km.upper - km.lower)
            pin.forwardKinematics(km.model, km.data, qc)
            d = pin.updateFramePlacement(km.model, km.data, fid).actInv(Mt)
            pe = float(np.linalg.norm(d.translation))
            re = 0.0 if position_only else float(np.linalg.norm(pin.log3(d.rotation)))
            # with the constraint on, penetrating configurations are neither answers nor stalls
            done = track.step(qc, pe, re) if self._avoid is None or not self.collides(qc) else None
            if done is True:
                return True, it, pe + re, qc
            if done is False or self.clock() >= deadline:
                return False, it, track.best_s, track.best_q
            try:
                self.solver.solve(True)
            except RuntimeError:  # placo raises RuntimeError when its QP is infeasible
                return False, it, track.best_s, track.best_q
            self.robot.update_kinematics()
        return False, max_iter, track.best_s, track.best_q
