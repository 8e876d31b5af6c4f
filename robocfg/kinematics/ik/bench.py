"""IK benchmark with TRAC-IK's protocol, our backends side by side with PyBullet's IK.

Protocol: ``n`` joint configurations drawn uniformly within the limits (seeded); targets = FK of
the frame (``ee`` = ee_link by default); every query starts from the midpoint of the limits;
success = position error ≤ 1e-5 m **and** rotation error ≤ 1e-5 rad **and** the answer within
the joint limits; time budget 5 ms per query; times include failures. The same targets go, in
the same run, to a reference solver handed in by the caller (the CLI passes
``pybullet.calculateInverseKinematics`` from :mod:`robocfg.sim.ik_reference`), whose answers are
scored with the same FK. Returns typed results; printing is the CLI's job.
"""

from __future__ import annotations

import platform
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from time import perf_counter, process_time
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.kinematics.model import KinematicModel

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


class ReferenceSolver(Protocol):
    """A reference IK run on the same targets: returns its :class:`BenchRow` (scored by :func:`score`)."""

    def __call__(self, robot: CheckedRobot, model: KinematicModel, targets: Sequence[np.ndarray],
                 seed_q: np.ndarray, frame: str) -> BenchRow: ...


def score(name: str, model: KinematicModel, targets: Sequence[np.ndarray], answers: Sequence[np.ndarray],
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
    return score(backend, model, targets, answers, times, process_time() - c0, frame, note)


def bench_ik(robot: CheckedRobot, n: int = 1000, backends: Sequence[str] | None = None, seed: int = 0,
             time_budget: float = 0.005, frame: str = "ee", reference: ReferenceSolver | None = None,
             n_by_backend: dict[str, int] | None = None, budget_clock: str = "wall",
             progress: Callable[[str], None] | None = None) -> BenchResult:
    """Run the protocol for ``backends`` (default: every registered one) and ``reference`` (if given).

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
    if reference is not None:
        if progress:
            progress(f"reference: {n} queries")
        result.rows.append(reference(robot, model, targets, seed_q, frame))
    result.load_average = (load0, _load())
    return result


def _load() -> float:
    import os

    try:
        return float(os.getloadavg()[0])
    except OSError:
        return 0.0
