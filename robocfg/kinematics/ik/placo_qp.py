"""``placo``: placo's KinematicsSolver (a QP per step) with joint limits.

placo's ``RobotWrapper`` always adds a floating base: it is placed at the mount pose and masked,
as are every non-arm joint (set to the model's locked values). The TCP is added to the URDF given
to placo as a fixed link, so its frame task acts on the same point as the other backends. Each
``solve(True)`` is one QP step followed by integration; steps repeat until the tolerance, a stall,
or the time budget. Self-collision avoidance is not enabled here (collision meshes are not
loaded): this backend answers the pure IK question like the others.

placo is imported when the solver is built.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np

from robocfg.kinematics.ik.common import (
    check_seed,
    check_target,
    finish,
    nearest_equivalent,
    search,
)
from robocfg.kinematics.ik.registry import register

if TYPE_CHECKING:
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
    """placo KinematicsSolver with a frame task (or a position task) and joint limits."""

    name = "placo"
    clock = staticmethod(perf_counter)  # what the time budget is measured with (thread_time: CPU)

    def __init__(self, model: KinematicModel, tol_pos: float = 1e-5, tol_rot: float = 1e-5,
                 max_iter: int = 100, stall_ratio: float = 0.9, stall_n: int = 5):
        import placo

        self.km = model
        self.tol_pos, self.tol_rot = tol_pos, tol_rot
        self.max_iter, self.stall_ratio, self.stall_n = max_iter, stall_ratio, stall_n
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
        self._task = None

    def _frame(self, frame: str) -> str:
        return PLACO_TCP if frame == "tcp" else self.km.frame_name(frame)

    def solve(self, target: np.ndarray, seed_q: np.ndarray, frame: str = "tcp",
              time_budget: float = 0.02, position_only: bool = False,
              rng: np.random.Generator | None = None) -> IKResult:
        import pinocchio as pin

        t0 = perf_counter()
        T = check_target(target)
        km = self.km
        q0 = check_seed(km, seed_q)
        fid = km.frame_id(frame)
        Mt = pin.SE3(T[:3, :3], T[:3, 3])
        if self._task is not None:
            self.solver.remove_task(self._task)
        name = self._frame(frame)
        if position_only:
            self._task = self.solver.add_position_task(name, T[:3, 3].copy())
        else:
            self._task = self.solver.add_frame_task(name, T.copy())
        self._task.configure("target", "soft", 1.0)

        def descend(q: np.ndarray, deadline: float):
            return self._descend(q, Mt, fid, position_only, deadline)

        best_q, iters, restarts = search(km, descend, q0, self.clock() + time_budget, rng, self.clock)
        return finish(km, self.name, nearest_equivalent(km, best_q, q0), Mt, fid, position_only, self.tol_pos, self.tol_rot,
                      t0, iters, restarts)

    def _set_q(self, q: np.ndarray) -> None:
        for name, v in zip(self.km.joint_names, q.tolist(), strict=True):
            self.robot.set_joint(name, v)
        self.robot.update_kinematics()

    def _get_q(self) -> np.ndarray:
        return np.array([self.robot.get_joint(n) for n in self.km.joint_names])

    def _descend(self, q, Mt, fid, position_only, deadline):
        import pinocchio as pin

        km = self.km
        self._set_q(q)
        best_s, best_q, ref_s, stall = math.inf, q, math.inf, 0
        for it in range(1, self.max_iter + 1):
            qc = km.lower + np.clip(self._get_q() - km.lower, 0.0, km.upper - km.lower)
            pin.forwardKinematics(km.model, km.data, qc)
            d = pin.updateFramePlacement(km.model, km.data, fid).actInv(Mt)
            pe = float(np.linalg.norm(d.translation))
            re = 0.0 if position_only else float(np.linalg.norm(pin.log3(d.rotation)))
            s = pe + re
            if s < best_s:
                best_s, best_q = s, qc
            if pe <= self.tol_pos and re <= self.tol_rot:
                return True, it, s, qc
            if s < ref_s * self.stall_ratio:
                ref_s, stall = s, 0
            else:
                stall += 1
                if stall >= self.stall_n:
                    return False, it, best_s, best_q
            if self.clock() >= deadline:
                return False, it, best_s, best_q
            try:
                self.solver.solve(True)
            except RuntimeError:  # placo raises RuntimeError when its QP is infeasible
                return False, it, best_s, best_q
            self.robot.update_kinematics()
        return False, self.max_iter, best_s, best_q
