"""Candidate grasp poses from an object cloud: antipodal contact pairs (both normals inside the
friction cone of the line joining them) and, about each pair's closing axis, several approach
directions, top-down first. World frame, m; poses in the GraspNet convention (x approach,
y closing, z = x × y). The first two steps of :func:`robocfg.grasp.antipodal.plan_grasps`.
"""

from __future__ import annotations

import math

import numpy as np

APPROACH_ANGLES_DEG = (0.0, 30.0, -30.0, 60.0, -60.0)
LEVEL_TILT = 0.05  # closing axes steeper than this (sine) also get a level variant
Pair = tuple[np.ndarray, np.ndarray]  # two contact points (3,), world m


def antipodal_pairs(P: np.ndarray, N: np.ndarray, w_max: float, mu: float, voxel: float, num_seeds: int,
                    rng: np.random.Generator, chunk: int = 64) -> tuple[list[Pair], int, int]:
    """For each of ``num_seeds`` seed points of the cloud ``P``/``N`` (N, 3; outward unit normals):
    its most antipodal partner and one random antipodal partner more than two voxels and at most
    ``w_max`` (m) away, both contact normals within the friction cone (half angle atan ``mu``) of
    the contact line; steep pairs also give a level variant. Returns (pairs, seeds drawn, seeds
    without a partner)."""
    n = len(P)
    cos_cone = math.cos(math.atan(mu))
    seeds = rng.choice(n, size=min(num_seeds, n), replace=False)
    lonely = 0
    out: list[Pair] = []
    for a in range(0, len(seeds), chunk):
        S = seeds[a : a + chunk]
        D = P[None, :, :] - P[S][:, None, :]  # (k, n, 3)
        dist = np.linalg.norm(D, axis=2)
        U = D / np.maximum(dist, 1e-12)[:, :, None]
        c1 = -np.einsum("kni,ki->kn", U, N[S])
        c2 = np.einsum("kni,ni->kn", U, N)
        good = (dist > 2 * voxel) & (dist <= w_max) & (c1 >= cos_cone) & (c2 >= cos_cone)
        quality = np.where(good, np.minimum(c1, c2), -np.inf)
        for r, i in enumerate(S):
            g = np.flatnonzero(good[r])
            if len(g) == 0:
                lonely += 1
                continue
            for j in {int(np.argmax(quality[r])), int(rng.choice(g))}:
                _add_pair(out, P[i], P[j])
    return out, len(seeds), lonely


def _add_pair(out: list[Pair], a: np.ndarray, b: np.ndarray) -> None:
    out.append((a, b))
    u = b - a
    if abs(u[2]) > LEVEL_TILT * np.linalg.norm(u) and np.linalg.norm(u[:2]) > 1e-6:
        # the same centre with a level closing axis: on round objects (any diameter is antipodal)
        # it keeps both fingers off the support; the closing check re-measures it
        c, h = (a + b) / 2, np.linalg.norm(u) / 2
        lev = np.array([u[0], u[1], 0.0]) / np.linalg.norm(u[:2])
        out.append((c - h * lev, c + h * lev))


def grasp_poses(pairs: list[Pair]) -> tuple[np.ndarray, np.ndarray]:
    """Centres (K, 3) and rotations (K, 3, 3): every pair × ``APPROACH_ANGLES_DEG`` about its axis,
    angle 0 being the approach closest to straight down."""
    if not pairs:
        return np.zeros((0, 3)), np.zeros((0, 3, 3))
    p1 = np.array([a for a, _ in pairs])
    p2 = np.array([b for _, b in pairs])
    y = p2 - p1
    y /= np.linalg.norm(y, axis=1, keepdims=True)
    down = np.array([0.0, 0.0, -1.0])
    e1 = down - (y @ down)[:, None] * y
    flat = np.linalg.norm(e1, axis=1) < 1e-3  # vertical closing axis: approach horizontally
    e1[flat] = np.cross(y[flat], [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(y, e1)
    c = (p1 + p2) / 2
    t = np.radians(APPROACH_ANGLES_DEG)
    a = np.cos(t)[None, :, None] * e1[:, None, :] + np.sin(t)[None, :, None] * e2[:, None, :]  # (K, A, 3)
    yy = np.broadcast_to(y[:, None, :], a.shape)
    R = np.stack([a, yy, np.cross(a, yy)], axis=-1).reshape(-1, 3, 3)
    C = np.repeat(c, len(t), axis=0)
    return C, R
