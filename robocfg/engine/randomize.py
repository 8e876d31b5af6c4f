"""The one seeded randomisation of spawned bodies that every task kind uses.

``place_randomly`` moves a body by up to ± ``xy_range`` (m) in x and y and turns it by up to
± ``yaw_range_deg`` about the world z axis, drawing three numbers from the episode's generator in
a fixed order (dx, dy, dyaw) so that the same (seed, k) places the body the same way everywhere.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robocfg.config.commands import Region
from robocfg.config.scene import Body


@dataclass(frozen=True)
class Placement:
    """A randomly placed copy of a body and the yaw (rad, about world z) it was turned by."""

    body: Body
    yaw: float


def place_randomly(body: Body, region: Region, rng: np.random.Generator) -> Placement:
    """``body`` shifted and turned within ``region``. An orientation given as Euler angles stays
    Euler angles with the yaw added (R = Rz·Ry·Rx, so that is a turn about world z); any other
    orientation is composed as a quaternion, R' = Rz(dyaw)·R."""
    dx, dy = rng.uniform(-1, 1, 2) * np.asarray(region.xy_range)
    dyaw = math.radians(rng.uniform(-1, 1) * region.yaw_range_deg)
    position = [body.position[0] + dx, body.position[1] + dy, body.position[2]]
    if body.euler_deg is not None:
        roll, pitch, yaw = body.euler_deg
        turned = math.degrees(math.radians(yaw) + dyaw)
        moved = body.model_copy(update={"position": position, "euler_deg": [roll, pitch, turned]})
    else:
        from robocfg.geometry import matrix_to_quat, quat_to_matrix

        c, s = math.cos(dyaw), math.sin(dyaw)
        Rz = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        quat = matrix_to_quat(Rz @ quat_to_matrix(body.quaternion_xyzw()))
        moved = body.model_copy(update={"position": position, "euler_deg": None, "quat_wxyz": None,
                                        "quat_xyzw": [float(v) for v in quat]})
    return Placement(moved, dyaw)
