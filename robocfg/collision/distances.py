"""Distances of every collision pair (robot–environment and robot–robot), computed by coal in one
pinocchio call; the nearest points and normal are read only for the pairs below a cut-off.

(A Python bounding-sphere broad phase was measured slower than coal on all 63 Panda pairs:
0.17 ms vs 0.08 ms per step.) Points and normals are in the world frame, metres.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PairDistance:
    pair: int  # index in the geometry model's collision pairs
    a: int  # geometry ids (a: the robot side)
    b: int
    distance: float  # m, negative when penetrating
    point_a: np.ndarray  # world (m)
    point_b: np.ndarray
    normal: np.ndarray  # unit, from a towards b (separation direction)


class DistanceField:
    """Distances for the collision pairs of ``geom_model`` attached to pinocchio ``model``."""

    def __init__(self, model, geom_model):
        import pinocchio as pin

        self.pin, self.model, self.geom = pin, model, geom_model
        self.data = model.createData()
        self.gdata = pin.GeometryData(geom_model)
        self.pairs = np.array([(p.first, p.second) for p in geom_model.collisionPairs], dtype=int).reshape(-1, 2)
        self.q = None

    def update(self, q_full: np.ndarray) -> None:
        """Remember the full configuration ``q_full`` (pinocchio order) for the next query."""
        self.q = np.asarray(q_full, dtype=float)

    def query(self, cutoff: float | np.ndarray) -> tuple[list[PairDistance], np.ndarray]:
        """(details of the pairs closer than ``cutoff`` (m; one value or one per pair), every
        pair's distance). Also leaves forward kinematics in ``self.data``."""
        pin = self.pin
        pin.computeDistances(self.model, self.data, self.geom, self.gdata, self.q)
        results = self.gdata.distanceResults
        dist = np.fromiter((r.min_distance for r in results), dtype=float, count=len(self.pairs))
        out = []
        for k in np.nonzero(dist < cutoff)[0]:
            k = int(k)
            r = results[k]
            pa, pb, n = r.getNearestPoint1(), r.getNearestPoint2(), np.asarray(r.normal)
            nn = float(n @ n)
            if not 0.5 < nn < 1.5:  # no usable normal: fall back to the nearest points
                diff = pb - pa
                n = diff / max(float(np.sqrt(diff @ diff)), 1e-12)
            out.append(PairDistance(k, int(self.pairs[k, 0]), int(self.pairs[k, 1]), float(dist[k]), pa, pb, n))
        return out, dist
