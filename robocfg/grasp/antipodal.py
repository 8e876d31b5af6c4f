"""Antipodal grasp candidates from an object point cloud with normals, scored
analytically instead of by a CNN.

Pipeline (world frame, m): (1) sample seed points; for each, find partners within the usable
finger gap whose contact line lies inside *both* friction cones (half angle atan μ), plus a level
variant of steep pairs; (2) around each contact axis, try several approach directions (top-down
first) → GraspNet-frame poses (x approach, y closing); (3) reject poses whose
gripper boxes, swept back along the approach by the pre-grasp stand-off, dip below the support
plane or contain a scene point; (4) re-measure what the closing fingers would really touch
(outermost object points in the finger sweep), re-centre, and re-check width, antipodality
(≥ ``min_antipodality``), patch size and edge curvature there; (5) reject grasps whose links,
closing down to the grasp width, dip below the support (linkages such as the Robotiq's swing
forward); (6) score = antipodality, Ferrari–Canny epsilon (gravity torque about the contact axis
included) and top-down preference; (7) non-maximum suppression; (8) closing knuckles/linkages vs
the cloud, then IK reachability (a callback) until ``top_k`` survive. Rejections are counted per
reason (``REASONS``). Steps 1–2 live in :mod:`robocfg.grasp.pairs`, the gripper-box tests of steps
3, 5 and 8 in :mod:`robocfg.grasp.clearance`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from robocfg.geometry import rotation_angle
from robocfg.grasp.clearance import above_support, closing_clear, collision_free, linkage_clear
from robocfg.grasp.gripper_model import GripperBoxes
from robocfg.grasp.pairs import antipodal_pairs, grasp_poses
from robocfg.grasp.quality import epsilon
from robocfg.kinematics.frames import Grasp

REASONS = ("not_antipodal", "too_wide", "collision", "slips_at_contact", "linkage_collision", "unreachable")
MIN_CONTACT_POINTS = 4  # cloud points a finger must find at its contact (a patch, not an edge)
MIN_FACING = 0.25  # a finger pad pushes only on points whose normal faces it by more than this (cosine)


@dataclass(frozen=True)
class PlannerSettings:
    """Planner knobs (m, rad). ``clearance``: free gap left on each side of the object when open;
    ``collision_margin``: boxes are inflated by this; ``nms_*``: two grasps closer than both
    thresholds are duplicates."""

    mu: float = 0.5
    num_candidates: int = 200
    top_k: int = 10
    standoff: float = 0.1
    voxel: float = 0.004
    clearance: float = 0.004
    collision_margin: float = 0.003
    nms_distance: float = 0.01
    nms_angle: float = math.radians(20.0)
    max_contact_curvature: float = 0.04  # surface variation: planes ≈ 0.002, a 3 cm sphere ≈ 0.01, edges ≥ 0.05
    min_antipodality: float = 0.25  # contact line within 3/4 of the friction cone at the re-measured contacts
    epsilon_pool: int = 4  # epsilon is computed for the best epsilon_pool·top_k by the cheaper terms
    max_poses: int = 1500


@dataclass
class Candidate:
    """A ranked grasp: ``grasp`` (GraspNet frame), ``score`` in [0, 1], its terms, the two contact
    points (world, m) and, once checked, the IK answer ``q`` of the grasp pose (arm joints)."""

    grasp: Grasp
    score: float
    antipodality: float
    epsilon: float
    top_down: float
    contacts: np.ndarray
    q: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {"center": [round(float(v), 5) for v in self.grasp.center],
                "approach": [round(float(v), 4) for v in self.grasp.approach()],
                "closing": [round(float(v), 4) for v in self.grasp.closing()],
                "width": round(float(self.grasp.width), 5), "score": round(self.score, 4),
                "antipodality": round(self.antipodality, 4), "epsilon": round(self.epsilon, 5),
                "top_down": round(self.top_down, 4)}


@dataclass
class PlanResult:
    """``candidates``: ranked, reachable (when a reach test was given), at most ``top_k``;
    ``poses``: grasp poses evaluated; ``rejected``: counts per reason (see ``REASONS``)."""

    candidates: list[Candidate]
    seeds: int
    poses: int
    rejected: dict[str, int] = field(default_factory=lambda: dict.fromkeys(REASONS, 0))
    suppressed: int = 0
    time_s: float = 0.0


Reach = Callable[[Grasp], tuple[Grasp, np.ndarray] | None]


def plan_grasps(points: np.ndarray, normals: np.ndarray, scene: np.ndarray, support_z: float | None,
                boxes: GripperBoxes, settings: PlannerSettings, rng: np.random.Generator,
                reach: Reach | None = None, curvature: np.ndarray | None = None) -> PlanResult:
    """Rank antipodal grasps on the object cloud ``points``/``normals`` (N, 3; outward unit
    normals), collision-checked against ``scene`` (M, 3: points of every body that is not the
    robot or the support, the object's included) and the horizontal support plane at height
    ``support_z`` (m; None: no support). ``reach(grasp)`` returns ``(grasp, q)`` (possibly turned
    half a turn about its approach) or None when the arm cannot get there. ``curvature`` (N,):
    surface variation per point; contacts whose patch averages above ``max_contact_curvature`` sit
    on an edge or corner (their blended normals look antipodal but slip) and are rejected."""
    t0 = time.perf_counter()
    s = settings
    res = PlanResult([], 0, 0)
    w_max = min(boxes.max_width, _finger_gap(boxes)) - 2 * s.clearance
    pairs, res.seeds, lonely = antipodal_pairs(points, normals, w_max, s.mu, s.voxel, s.num_candidates, rng)
    res.rejected["not_antipodal"] += lonely
    centers, rots = grasp_poses(pairs)
    centers, rots = centers[: s.max_poses], rots[: s.max_poses]
    res.poses = len(centers)
    if not len(centers):
        res.time_s = time.perf_counter() - t0
        return res
    swept = boxes.swept(s.standoff).inflated(s.collision_margin)
    free = np.ones(len(centers), bool)
    if support_z is not None:
        free &= above_support(centers, rots, swept, support_z)
    free[free] = collision_free(centers[free], rots[free], scene, swept)
    res.rejected["collision"] += int((~free).sum())
    centers, rots = centers[free], rots[free]
    com = points.mean(axis=0)
    rho = max(float(np.max(np.linalg.norm(points - com, axis=1))), 0.01)
    curv = np.zeros(len(points)) if curvature is None else np.asarray(curvature, float)
    cands = _closing_check(centers, rots, points, normals, curv, boxes, w_max, s, res)
    if support_z is not None and boxes.samples:
        clear = closing_clear([c.grasp for c in cands], boxes, s.collision_margin, support_z)
        res.rejected["collision"] += int((~clear).sum())
        cands = [c for c, ok in zip(cands, clear, strict=True) if ok]
    cands.sort(key=lambda c: -c.score)
    pool = cands[: s.epsilon_pool * s.top_k]
    eps_ref = epsilon([-rho, 0, 0], [-1, 0, 0], [rho, 0, 0], [1, 0, 0], [0, 0, 0], s.mu, rho)
    for c in pool:
        p1, p2 = c.contacts
        n1, n2 = -c.grasp.closing(), c.grasp.closing()
        n1, n2 = _nearest_normal(points, normals, p1, n1), _nearest_normal(points, normals, p2, n2)
        c.epsilon = epsilon(p1, n1, p2, n2, com, s.mu, rho)
        c.score = _score(c.antipodality, min(1.0, c.epsilon / eps_ref), c.top_down)
    pool.sort(key=lambda c: -c.score)
    kept: list[Candidate] = []
    for c in pool + cands[len(pool) :]:  # the rest (epsilon not computed) only if the pool runs dry
        if any(_duplicate(c.grasp, k.grasp, s) for k in kept):
            res.suppressed += 1
            continue
        if not linkage_clear(c.grasp, boxes, scene):
            res.rejected["linkage_collision"] += 1
            continue
        if reach is not None:
            ans = reach(c.grasp)
            if ans is None:
                res.rejected["unreachable"] += 1
                continue
            c.grasp, c.q = ans
        kept.append(c)
        if len(kept) >= s.top_k:
            break
    res.candidates = kept
    res.time_s = time.perf_counter() - t0
    return res


def _finger_gap(boxes: GripperBoxes) -> float:
    """Measured gap (m) between the inner faces of the open finger boxes."""
    f = boxes.finger
    lo_y, hi_y = boxes.lo[f, 1], boxes.hi[f, 1]
    pos, neg = lo_y[lo_y > 0], hi_y[hi_y < 0]
    if len(pos) and len(neg):
        return float(pos.min() - neg.max())
    return boxes.max_width


def _closing_check(centers, rots, P, N, curv, boxes: GripperBoxes, w_max, s: PlannerSettings,
                   res: PlanResult, chunk: int = 128) -> list[Candidate]:
    """What the closing fingers touch: the outermost object points (along ±y) inside the fingers'
    sweep; re-centre on them and re-check width and antipodality (≥ ``min_antipodality``) there."""
    x0, x1 = boxes.finger_depth()
    z0, z1 = boxes.finger_height()
    half_gap = _finger_gap(boxes) / 2
    cos_cone = math.cos((1.0 - s.min_antipodality) * math.atan(s.mu))
    band = s.voxel
    out = []
    for a in range(0, len(centers), chunk):
        C, R = centers[a : a + chunk], rots[a : a + chunk]
        L = (P[None, :, :] - C[:, None, :]) @ R  # (k, N, 3) in each grasp frame
        m = (L[..., 0] >= x0) & (L[..., 0] <= x1) & (L[..., 2] >= z0) & (L[..., 2] <= z1) & (np.abs(L[..., 1]) < half_gap)
        enough = m.sum(axis=1) >= 2
        y = L[..., 1]
        lo = np.where(m, y, np.inf).min(axis=1)
        hi = np.where(m, y, -np.inf).max(axis=1)
        # The contact patch: points within a voxel of the outermost ones that face the pad. Points
        # whose normal is (nearly) perpendicular to the closing axis — the top face next to a side
        # face, say — are grazed, not pressed: blending their normals in would tilt the contact
        # normal of every thin object and make the score hinge on which grid row a window catches.
        n_y = np.einsum("nj,kj->kn", N, R[:, :, 1])  # each point's normal along each grasp's closing axis
        m_lo = (m & (y <= lo[:, None] + band) & (n_y < -MIN_FACING)).astype(float)
        m_hi = (m & (y >= hi[:, None] - band) & (n_y > MIN_FACING)).astype(float)
        support_lo, support_hi = m_lo.sum(axis=1), m_hi.sum(axis=1)
        edge = np.maximum(m_lo @ curv / np.maximum(support_lo, 1), m_hi @ curv / np.maximum(support_hi, 1))
        n_lo = m_lo @ N
        n_hi = m_hi @ N
        n_lo /= np.maximum(np.linalg.norm(n_lo, axis=1, keepdims=True), 1e-12)
        n_hi /= np.maximum(np.linalg.norm(n_hi, axis=1, keepdims=True), 1e-12)
        ycol = R[:, :, 1]
        c_lo = -np.einsum("ki,ki->k", n_lo, ycol)
        c_hi = np.einsum("ki,ki->k", n_hi, ycol)
        p_lo = (m_lo @ P) / np.maximum(m_lo.sum(axis=1, keepdims=True), 1)
        p_hi = (m_hi @ P) / np.maximum(m_hi.sum(axis=1, keepdims=True), 1)
        for k in range(len(C)):
            if not enough[k] or min(support_lo[k], support_hi[k]) < MIN_CONTACT_POINTS or edge[k] > s.max_contact_curvature:
                res.rejected["slips_at_contact"] += 1
                continue
            if hi[k] - lo[k] > w_max:
                res.rejected["too_wide"] += 1
                continue
            worst = min(c_lo[k], c_hi[k])
            if worst < cos_cone:
                res.rejected["slips_at_contact"] += 1
                continue
            antip = 1.0 - math.acos(min(1.0, worst)) / math.atan(s.mu)
            center = C[k] + R[k][:, 1] * (lo[k] + hi[k]) / 2
            top_down = max(0.0, float(-R[k][2, 0]))
            g = Grasp(center, R[k], float(hi[k] - lo[k]))
            out.append(Candidate(g, _score(antip, 0.0, top_down), antip, 0.0, top_down, np.array([p_lo[k], p_hi[k]])))
    return out


def _score(antip: float, eps_norm: float, top_down: float) -> float:
    return 0.45 * antip + 0.35 * eps_norm + 0.2 * top_down


def _nearest_normal(P, N, p, fallback) -> np.ndarray:
    d = np.linalg.norm(P - p, axis=1)
    k = np.argsort(d)[:5]
    n = N[k].mean(axis=0)
    return _unit(n) if np.linalg.norm(n) > 1e-6 else np.asarray(fallback, float)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / max(float(np.linalg.norm(v)), 1e-12)


def _duplicate(a: Grasp, b: Grasp, s: PlannerSettings) -> bool:
    if np.linalg.norm(a.center - b.center) > s.nms_distance:
        return False
    flip = np.diag([1.0, -1.0, -1.0])  # half a turn about the approach: the same parallel-jaw grasp
    ang = min(rotation_angle(a.rotation, b.rotation), rotation_angle(a.rotation, b.rotation @ flip))
    return ang < s.nms_angle
