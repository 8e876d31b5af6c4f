"""robocfg.motion.reactive.tool_roll: the roll about an axis-symmetric tool's axis taken out."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from robocfg.motion.reactive.tool_roll import axis_angle, nearest_roll


def _angle(R: np.ndarray) -> float:
    return float(np.linalg.norm(Rotation.from_matrix(R).as_rotvec()))


def test_nearest_roll_is_the_best_roll_and_leaves_the_tool_axis_angle():
    rng = np.random.default_rng(3)
    rolls = np.linspace(-np.pi, np.pi, 361)
    for k in range(60):
        axis = k % 3
        Rt = Rotation.random(random_state=rng).as_matrix()
        Rc = Rotation.random(random_state=rng).as_matrix()
        if k % 4 == 0:  # a half turn about the tool axis, the default follow-target start on the iiwa
            Rc = Rt @ Rotation.from_rotvec(np.pi * np.eye(3)[axis]).as_matrix()
        R = nearest_roll(Rt, Rc, axis)
        assert np.allclose(R[:, axis], Rt[:, axis], atol=1e-9)  # turned about its own tool axis only
        left = _angle(R.T @ Rc)
        best = min(_angle((Rt @ Rotation.from_rotvec(a * np.eye(3)[axis]).as_matrix()).T @ Rc) for a in rolls)
        assert left <= best + 1e-6
        assert abs(left - axis_angle(Rt, Rc, axis)) < 1e-6
    assert abs(axis_angle(np.eye(3), Rotation.from_rotvec([0, 0, 2.0]).as_matrix(), 2)) < 1e-12
    assert abs(axis_angle(np.eye(3), Rotation.from_rotvec([0.3, 0, 0]).as_matrix(), 2) - 0.3) < 1e-9
