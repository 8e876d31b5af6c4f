"""Analytic grasp quality for two frictional contacts (no learning): antipodality against the
friction cone and a Ferrari–Canny epsilon metric of the grasp wrench space.

Contacts are soft fingers: a Coulomb friction cone (half angle atan μ, ``CONE_EDGES`` edges) plus a
small torsional friction moment about the normal, so two contacts span all six wrench directions.
Torques are divided by a characteristic length ``rho`` (m, the object's radius) so forces and
torques are comparable; epsilon is the radius of the largest wrench ball around the origin inside
the convex hull of the unit contact wrenches (0 when the grasp is not force closure).
"""

from __future__ import annotations

import math

import numpy as np

CONE_EDGES = 4  # 4 edges: the 6-D hull costs ≈ 3 ms (8 edges ≈ 3× more) for a close bound
TORSION_RADIUS = 0.005  # m: radius of the soft-finger contact patch for torsional friction


def cone_angles(p1, n1, p2, n2) -> tuple[float, float]:
    """Angles (rad) between the contact line and each inward normal (n1, n2 are *outward* unit
    normals at contacts p1, p2). Both ≤ atan μ ⇔ the pair is antipodal (force closure with friction)."""
    u = np.asarray(p2, float) - np.asarray(p1, float)
    u /= max(float(np.linalg.norm(u)), 1e-12)
    c1 = float(np.clip(-np.dot(n1, u), -1, 1))  # finger 1 pushes along +u into the object
    c2 = float(np.clip(np.dot(n2, u), -1, 1))  # finger 2 pushes along −u
    return math.acos(c1), math.acos(c2)


def antipodality(p1, n1, p2, n2, mu: float) -> float:
    """1 for perfectly opposed normals along the contact line, 0 at the friction-cone edge, < 0 outside."""
    a = max(cone_angles(p1, n1, p2, n2))
    return 1.0 - a / math.atan(mu)


def contact_wrenches(p, n_in, com, mu: float, rho: float) -> np.ndarray:
    """(CONE_EDGES + 2, 6) unit wrenches of one soft-finger contact at ``p`` pushing along the inward
    unit normal ``n_in``; torques about ``com`` divided by ``rho``."""
    n = np.asarray(n_in, float) / np.linalg.norm(n_in)
    t1 = np.cross(n, [1.0, 0.0, 0.0])
    if np.linalg.norm(t1) < 1e-6:
        t1 = np.cross(n, [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    phi = np.arange(CONE_EDGES) * 2 * math.pi / CONE_EDGES
    f = n + mu * (np.cos(phi)[:, None] * t1 + np.sin(phi)[:, None] * t2)
    f /= np.linalg.norm(f, axis=1, keepdims=True)
    r = np.asarray(p, float) - np.asarray(com, float)
    w = np.hstack([f, np.cross(r, f) / rho])
    tors = mu * TORSION_RADIUS / rho
    w_t = np.array([[0, 0, 0, *(tors * n)], [0, 0, 0, *(-tors * n)]])
    return np.vstack([w, w_t])


def epsilon(p1, n1, p2, n2, com, mu: float, rho: float) -> float:
    """Ferrari–Canny epsilon (L1 grasp wrench space) of the contact pair; n1, n2 are *outward*
    normals. 0 when the origin is not strictly inside the hull (no force closure)."""
    from scipy.spatial import ConvexHull, QhullError

    # a finger pushes along the inward normal; use the measured normals (friction does the rest)
    W = np.vstack([contact_wrenches(p1, -np.asarray(n1, float), com, mu, rho),
                   contact_wrenches(p2, -np.asarray(n2, float), com, mu, rho)])
    try:
        hull = ConvexHull(W)
    except (QhullError, ValueError):
        return 0.0
    offsets = hull.equations[:, -1]  # n·x + b ≤ 0 inside; distance of origin to a facet is −b
    if np.any(offsets >= 0):
        return 0.0
    return float(np.min(-offsets))
