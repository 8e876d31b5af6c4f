"""A home pose for a robot that has none yet (``robocfg new-robot``): the tool pointing straight
down over the workspace in front of the robot, found by IK.

The reach is estimated from forward kinematics over joint samples (the largest horizontal TCP
distance from the first joint's axis); targets are tried at fractions of it in front of the base
(+x of the root link) and at heights above the base, with the fingers closing along world −y, then
x (−y first: the tool frame of the default tasks' orientation ``[180, 0, 0]``, so a drafted arm
starts where follow-target and trajectory point the tool; a one-jaw gripper is not symmetric, and
half a turn about the tool axis from the target it reached a wrist limit while turning). Among the
IK answers that converge for the first target and closing direction that work, the one furthest
from the joint limits wins; a target whose answers all come within ``LIMIT_MARGIN`` of a limit is passed
over for the next (so ``home_std`` has room), and used only when no target does better. Frames: the robot's root link at the world origin,
metres, radians.
"""

from __future__ import annotations

import numpy as np

from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp, grasp_rotation
from robocfg.kinematics.model import KinematicModel

REACH_SAMPLES = 400
DISTANCES = (0.5, 0.4, 0.6, 0.3)  # fractions of the reach, in front of the base
HEIGHTS = (0.3, 0.2, 0.4, 0.1)  # fractions of the reach, above the first joint's origin
IK_BUDGET = 0.2  # s per IK call: not consulted while IK_ITERATIONS bounds the search
# LM iterations per IK call over all restarts: the search ends by count, not by the clock, so a
# draft's home is the same on a loaded machine (a converging target takes < 10; a failing one ran
# 840-2260 in 0.2 s on a quiet 2-core machine)
IK_ITERATIONS = 1000
EXTRA_SEEDS = 4  # random IK seeds besides home and mid-limits (a UR's both are all zeros: one answer)
BELOW_BASE = 0.001  # m
LIMIT_MARGIN = 0.16  # rad: a home this far inside every limit leaves room for 3 × the draft's home_std (0.05)


def reach(model: KinematicModel, rng: np.random.Generator) -> tuple[float, float]:
    """(horizontal reach m, mid-height m of the reachable TCP positions) from FK over random joint samples."""
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    pts = np.array([model.fk(q)[:3, 3] for q in rng.uniform(lo, hi, (REACH_SAMPLES, model.nq))])
    z0 = float(pts[:, 2].min() + pts[:, 2].max()) / 2
    return float(np.max(np.linalg.norm(pts[:, :2], axis=1))), z0


def find_home(model: KinematicModel, seed: int = 0) -> np.ndarray | None:
    """Joint values (arm order) with the tool pointing down over the workspace, or None when no
    target in front of the robot is reachable with the tool down."""
    solver = model.solver()
    cap, solver.max_total_iter = solver.max_total_iter, IK_ITERATIONS
    try:
        return _find_home(model, np.random.default_rng(seed))
    finally:
        solver.max_total_iter = cap


def _find_home(model: KinematicModel, rng: np.random.Generator) -> np.ndarray | None:
    r, z0 = reach(model, rng)
    arm = model.robot.config.arm() if model.robot is not None else None
    if arm is None:
        return None
    lo = np.where(np.isfinite(model.lower), model.lower, -np.pi)
    hi = np.where(np.isfinite(model.upper), model.upper, np.pi)
    seeds = [np.clip(np.array(model.home, float), lo, hi), (lo + hi) / 2, *rng.uniform(lo, hi, (EXTRA_SEEDS, model.nq))]
    fallback = None
    for d in DISTANCES:
        for h in HEIGHTS:
            centre = np.array([d * r, 0.0, z0 + (h - 0.3) * r])
            for closing in ((0.0, -1.0, 0.0), (1.0, 0.0, 0.0)):  # −y preferred: x only when −y has no clear answer
                grasp = Grasp(centre, grasp_rotation(np.array([0.0, 0.0, -1.0]), np.array(closing)), 0.0)
                target = ee_pose_from_grasp(grasp, arm)
                best, best_score = None, np.inf
                for s in seeds:
                    res = model.ik(target, seed_q=s, frame="ee", time_budget=IK_BUDGET, rng=rng)
                    q = _wrapped(res.q, model)
                    if not res.converged or not model.within_limits(q) or not _above_base(q, model):
                        continue
                    score = _limit_score(q, model)
                    if score < best_score:
                        best, best_score = q, score
                if best is not None and _clear_of_limits(best, model):
                    return best
                fallback = best if fallback is None else fallback
    return fallback


def _wrapped(q: np.ndarray, model: KinematicModel) -> np.ndarray:
    """``q`` with every joint at least a full turn wide (``model.wrap``) taken into [−π, π): the
    same pose, and a home nearer the middle of such a joint's range (IK may answer 4.89 for −1.39)."""
    q = np.asarray(q, float)
    return np.where(model.wrap, (q + np.pi) % (2 * np.pi) - np.pi, q)


def _above_base(q: np.ndarray, model: KinematicModel) -> bool:
    """Every arm joint's origin at or above the root link's origin (``BELOW_BASE`` m of slack): an
    answer with the elbow under the plane the robot stands on (the drafted UR10's elbow-down
    answer, 0.21 m into the floor) is no home."""
    import pinocchio as pin

    pin.forwardKinematics(model.model, model.data, model._q(np.asarray(q, float)))
    z0 = float(model.base_pose[2, 3])
    return all(float(model.data.oMi[j].translation[2]) >= z0 - BELOW_BASE for j in range(1, model.model.njoints))


def _clear_of_limits(q: np.ndarray, model: KinematicModel) -> bool:
    """Every bounded joint at least LIMIT_MARGIN from its limits (room for the draft's home_std)."""
    bounded = np.isfinite(model.lower) & np.isfinite(model.upper)
    if model.continuous is not None:
        bounded &= ~model.continuous
    return bool(np.all(((q - model.lower) >= LIMIT_MARGIN) | ~bounded) and np.all(((model.upper - q) >= LIMIT_MARGIN) | ~bounded))


def _limit_score(q: np.ndarray, model: KinematicModel) -> float:
    """Sum of squared normalised distances from mid-range (0 at the middle, 1 at a limit) over bounded joints."""
    bounded = np.isfinite(model.lower) & np.isfinite(model.upper) & (model.upper - model.lower < 2 * np.pi - 1e-6)
    if model.continuous is not None:
        bounded &= ~model.continuous
    half = (model.upper - model.lower) / 2
    mid = (model.upper + model.lower) / 2
    return float(np.sum(((q - mid)[bounded] / half[bounded]) ** 2))
