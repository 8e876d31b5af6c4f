"""IK benchmark with TRAC-IK's protocol, our backends side by side with PyBullet's IK.

Protocol: ``n`` joint configurations drawn uniformly within the limits (seeded); targets = FK of
the frame (``ee`` = ee_link by default); every query starts from the midpoint of the limits;
success = position error ≤ 1e-5 m **and** rotation error ≤ 1e-5 rad **and** the answer within
the joint limits; time budget 5 ms per query; times include failures. The same targets go, in
the same run, to ``pybullet.calculateInverseKinematics`` (200 iterations, residual threshold
1e-8, limits passed as lowerLimits/upperLimits/jointRanges/restPoses, rest pose = seed), whose
answers are scored with the same FK. Returns typed results; printing is the CLI's job.
"""

from __future__ import annotations

import platform
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from time import perf_counter, process_time
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.kinematics.model import KinematicModel

PYBULLET_ROW = "pybullet"
TOL_POS, TOL_ROT = 1e-5, 1e-5  # m, rad
LOOSE_POS, LOOSE_ROT = 1e-3, 1e-2  # m, rad


@dataclass
class BenchRow:
    """One backend's figures (times in ms, rates in %)."""

    backend: str
    n: int
    success_pct: float  # ≤ 1e-5 m, ≤ 1e-5 rad, within limits
    success_loose_pct: float  # ≤ 1 mm, ≤ 0.01 rad, within limits
    outside_limits_pct: float  # answers outside the joint limits
    mean_ms: float
    median_ms: float
    p95_ms: float
    median_pos_err: float  # m
    cpu_mean_ms: float = 0.0  # CPU time of this process per query (excludes time lost to other processes)
    note: str = ""


@dataclass
class BenchResult:
    robot: str
    frame: str
    n: int
    seed: int
    time_budget_s: float
    budget_clock: str = "wall"
    rows: list[BenchRow] = field(default_factory=list)
    load_average: tuple[float, float] = (0.0, 0.0)  # 1-min load average before and after the run
    machine: str = field(default_factory=lambda: f"{platform.processor() or platform.machine()}, {_ncpu()} CPUs")


def _ncpu() -> int:
    import os

    return os.cpu_count() or 1


def make_targets(model: KinematicModel, n: int, seed: int, frame: str) -> tuple[np.ndarray, list[np.ndarray]]:
    """(configurations (n, nq), FK targets) with configurations uniform within the limits."""
    rng = np.random.default_rng(seed)
    Q = rng.uniform(model.lower, model.upper, (n, model.nq))
    return Q, [model.fk(q, frame) for q in Q]


def _row(name: str, model: KinematicModel, targets: Sequence[np.ndarray], answers: Sequence[np.ndarray],
         times: Sequence[float], cpu_s: float, frame: str, note: str = "") -> BenchRow:
    from robocfg.kinematics.ik.common import residuals

    ok = loose = outside = 0
    pos_errs = []
    for T, q in zip(targets, answers, strict=True):
        pe, re = residuals(model.fk(q, frame), T)
        inside = model.within_limits(q, tol=1e-9)
        ok += pe <= TOL_POS and re <= TOL_ROT and inside
        loose += pe <= LOOSE_POS and re <= LOOSE_ROT and inside
        outside += not inside
        pos_errs.append(pe)
    t = np.asarray(times) * 1e3
    n = len(targets)
    return BenchRow(name, n, 100 * ok / n, 100 * loose / n, 100 * outside / n, float(t.mean()),
                    float(np.median(t)), float(np.percentile(t, 95)), float(np.median(pos_errs)),
                    1e3 * cpu_s / n, note)


def run_backend(model: KinematicModel, backend: str, targets: Sequence[np.ndarray], seed_q: np.ndarray,
                frame: str, time_budget: float, seed: int, budget_clock: str = "wall") -> BenchRow:
    """Our backend on every target (one warm-up query first, not counted).

    ``budget_clock``: "wall" (the protocol) or "cpu" (the budget counts this thread's CPU time, so
    time lost to other processes on a shared machine does not end a search; times stay wall-clock).
    """
    from time import thread_time

    rng = np.random.default_rng(seed)
    solver = model.solver(backend)
    solver.clock = thread_time if budget_clock == "cpu" else perf_counter
    model.ik(targets[0], seed_q, frame=frame, backend=backend, time_budget=time_budget, rng=rng)
    answers, times = [], []
    c0 = process_time()
    for T in targets:
        t0 = perf_counter()
        res = model.ik(T, seed_q, frame=frame, backend=backend, time_budget=time_budget, rng=rng)
        times.append(perf_counter() - t0)
        answers.append(res.q)
    solver.clock = perf_counter
    note = "budget on CPU time" if budget_clock == "cpu" else ""
    return _row(backend, model, targets, answers, times, process_time() - c0, frame, note)


def run_pybullet(robot: CheckedRobot, model: KinematicModel, targets: Sequence[np.ndarray], seed_q: np.ndarray,
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
        dof_index, link_index, lower, upper, rest = {}, {}, [], [], []
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
            pos, quat = _pos_quat(T_ee)
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
    return _row(PYBULLET_ROW, model, targets, answers, times, cpu, frame, note)


def _pos_quat(T: np.ndarray) -> tuple[list[float], list[float]]:
    import pinocchio as pin

    q = pin.Quaternion(T[:3, :3].copy())
    return T[:3, 3].tolist(), [q.x, q.y, q.z, q.w]


def bench_ik(robot: CheckedRobot, n: int = 1000, backends: Sequence[str] | None = None, seed: int = 0,
             time_budget: float = 0.005, frame: str = "ee", pybullet: bool = True,
             n_by_backend: dict[str, int] | None = None, budget_clock: str = "wall",
             progress: Callable[[str], None] | None = None) -> BenchResult:
    """Run the protocol for ``backends`` (default: every registered one) and PyBullet's IK.

    ``n_by_backend`` lets a slow backend run on the first k targets only (its row says so).
    """
    from robocfg.kinematics.ik.registry import known_backends
    from robocfg.kinematics.model import KinematicModel

    model = KinematicModel.from_robot(robot)
    names = list(backends) if backends else known_backends()
    _, targets = make_targets(model, n, seed, frame)
    seed_q = model.mid
    load0 = _load()
    result = BenchResult(robot=robot.config.name, frame=frame, n=n, seed=seed, time_budget_s=time_budget,
                         budget_clock=budget_clock)
    for name in names:
        k = min(n, (n_by_backend or {}).get(name, n))
        if progress:
            progress(f"{name}: {k} queries")
        row = run_backend(model, name, targets[:k], seed_q, frame, time_budget, seed, budget_clock)
        if k < n:
            row.note = "; ".join(x for x in (row.note, f"first {k} of the {n} targets") if x)
        result.rows.append(row)
    if pybullet:
        if progress:
            progress(f"{PYBULLET_ROW}: {n} queries")
        result.rows.append(run_pybullet(robot, model, targets, seed_q, frame))
    result.load_average = (load0, _load())
    return result


def _load() -> float:
    import os

    try:
        return float(os.getloadavg()[0])
    except OSError:
        return 0.0
