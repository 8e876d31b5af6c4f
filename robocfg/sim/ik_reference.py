"""PyBullet's own IK (``calculateInverseKinematics``) as the reference row of ``robocfg bench ik``.

It lives on the simulator side because it needs a PyBullet body; the benchmark protocol in
:mod:`robocfg.kinematics.ik.bench` receives it as its ``reference``. Settings: 200 iterations,
residual threshold 1e-8, the joint limits passed as lowerLimits/upperLimits/jointRanges/
restPoses, rest pose = the seed; every query starts from the seed (state reset before each call).
Its answers are scored by the same FK as our backends.
"""

from __future__ import annotations

from time import perf_counter, process_time
from typing import TYPE_CHECKING

import numpy as np

from robocfg.geometry import matrix_to_pose
from robocfg.kinematics.ik.bench import BenchRow, score

if TYPE_CHECKING:
    from collections.abc import Sequence

    from robocfg.checks.robot import CheckedRobot
    from robocfg.kinematics.model import KinematicModel

PYBULLET_ROW = "pybullet"


def reference_row(robot: CheckedRobot, model: KinematicModel, targets: Sequence[np.ndarray], seed_q: np.ndarray,
                 frame: str, max_iter: int = 200, threshold: float = 1e-8) -> BenchRow:
    """``p.calculateInverseKinematics`` on the same targets (state reset to the seed before each call)."""
    import pybullet as p

    if frame not in ("ee", model.ee_link):
        T_ee_frame = np.linalg.inv(model.fk(seed_q, "ee")) @ model.fk(seed_q, frame)
    else:
        T_ee_frame = np.eye(4)
    cid = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(robot.urdf_path), useFixedBase=True, physicsClientId=cid)
        dof_index: dict[str, tuple[int, int]] = {}
        link_index: dict[str, int] = {}
        lower: list[float] = []
        upper: list[float] = []
        rest: list[float] = []
        arm_set = set(model.joint_names)
        for i in range(p.getNumJoints(body, physicsClientId=cid)):
            info = p.getJointInfo(body, i, physicsClientId=cid)
            name, jtype = info[1].decode(), info[2]
            link_index[info[12].decode()] = i
            if jtype == p.JOINT_FIXED:
                continue
            dof_index[name] = (len(lower), i)
            if name in arm_set:
                k = model.joint_names.index(name)
                lo, hi, r = model.lower[k], model.upper[k], seed_q[k]
            else:
                v = model.locked.get(name, 0.0)
                lo, hi, r = v, v, v
            lower.append(float(lo))
            upper.append(float(hi))
            rest.append(float(r))
        ranges = [max(h - lo, 1e-6) for lo, h in zip(lower, upper, strict=True)]
        arm_dofs = [dof_index[n][0] for n in model.joint_names]
        ee = link_index[model.ee_link]
        state = {name: (rest[d], i) for name, (d, i) in dof_index.items()}
        answers, times = [], []
        cpu = 0.0
        for T in targets:
            T_ee = T @ np.linalg.inv(T_ee_frame)
            for v, i in state.values():
                p.resetJointState(body, i, v, physicsClientId=cid)
            pos, quat = (v.tolist() for v in matrix_to_pose(T_ee))
            c0, t0 = process_time(), perf_counter()
            sol = p.calculateInverseKinematics(body, ee, pos, quat, lowerLimits=lower, upperLimits=upper,
                                               jointRanges=ranges, restPoses=rest, maxNumIterations=max_iter,
                                               residualThreshold=threshold, physicsClientId=cid)
            times.append(perf_counter() - t0)
            cpu += process_time() - c0
            answers.append(np.array([sol[d] for d in arm_dofs]))
    finally:
        p.disconnect(cid)
    note = f"calculateInverseKinematics, {max_iter} iterations, threshold {threshold:g}, limits passed"
    return score(PYBULLET_ROW, model, targets, answers, times, cpu, frame, note)
