"""GripperBoxes.linkage_hits: the bounds test that passes over far link boxes gives the same
answers as testing every point in every box."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.geometry import quat_to_matrix
from robocfg.grasp.gripper_model import GripperBoxes, GripperSample
from robocfg.sim.link_boxes import OrientedBox


def _every_point(boxes: GripperBoxes, points: np.ndarray, width: float, margin: float) -> bool:
    """The box test on every point of every non-finger box (no bounds test)."""
    for s in boxes.samples:
        if s.gap < width:
            continue
        for R, t, lo, hi, touches in s.obbs:
            if touches:
                continue
            local = (points - t) @ R
            if np.any(np.all((local >= lo - margin) & (local <= hi + margin), axis=1)):
                return True
    return False


def _boxes(rng: np.random.Generator) -> GripperBoxes:
    samples = []
    for gap in (0.08, 0.05, 0.02):
        obbs = []
        for k in range(4):
            q = rng.normal(size=4)
            R = quat_to_matrix(q / np.linalg.norm(q))
            lo = -rng.uniform(0.005, 0.04, 3)
            obbs.append(OrientedBox(R, rng.uniform(-0.1, 0.1, 3), lo, lo + rng.uniform(0.01, 0.08, 3), k == 3))
        samples.append(GripperSample(gap, np.zeros((4, 3)), np.zeros((4, 3)), tuple(obbs)))
    return GripperBoxes(np.zeros((4, 3)), np.zeros((4, 3)), ("a", "b", "c", "d"), np.array([False] * 3 + [True]),
                        0.08, tuple(samples))


@pytest.mark.parametrize("seed", range(6))
def test_linkage_hits_same_as_testing_every_point(seed):
    rng = np.random.default_rng(seed)
    boxes = _boxes(rng)
    answers = []
    for trial in range(300):
        margin = (0.0, 0.001)[trial % 2]
        width = rng.uniform(0.0, 0.09)
        # a small cloud somewhere near the boxes, sometimes with a point just inside or just
        # outside a box's face (where a bounds test off by a rounding would differ)
        points = rng.uniform(-0.02, 0.02, (int(rng.integers(1, 40)), 3)) + rng.uniform(-0.2, 0.2, 3)
        if trial % 3 == 0:
            s = boxes.samples[int(rng.integers(0, 3))]
            R, t, lo, hi, _ = s.obbs[int(rng.integers(0, 3))]
            corner = np.where(rng.random(3) < 0.5, lo - margin, hi + margin)
            nudge = (1.0 if trial % 2 else -1.0) * 1e-12 * np.sign(corner - (lo + hi) / 2)
            points[0] = t + R @ (corner + nudge)
        want = _every_point(boxes, points, width, margin)
        assert boxes.linkage_hits(points, width, margin) == want
        answers.append(want)
    assert any(answers) and not all(answers)  # both answers occurred
    assert boxes.linkage_hits(np.zeros((0, 3)), 0.0, 0.001) is False
