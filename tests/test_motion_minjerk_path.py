"""MinJerkPath: what a played move samples is evaluate()'s positions and velocities, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.motion.limits import JointLimits
from robocfg.motion.minjerk_path import MinJerkPath


@pytest.mark.parametrize("k", [2, 3, 4, 7])
def test_positions_velocities_are_evaluates_bits(k):
    rng = np.random.default_rng(k)
    W = np.cumsum(rng.normal(0.0, 0.2, (k, 7)), axis=0)
    limits = JointLimits(names=tuple("abcdefg"), lower=np.full(7, -4.0), upper=np.full(7, 4.0),
                         velocity=np.full(7, 2.0), acceleration=np.full(7, 6.0))
    path = MinJerkPath(W, limits)
    t = np.arange(1, int(path.duration * 240) + 5) / 240  # past the end too (clipped)
    q, qd = path.positions_velocities(t)
    q_ref, qd_ref, _ = path.evaluate(t)
    assert q.shape == q_ref.shape and qd.shape == qd_ref.shape
    assert q.tobytes() == q_ref.tobytes() and qd.tobytes() == qd_ref.tobytes()
    t_few = np.linspace(-0.1, path.duration + 0.1, 41)
    assert path.positions(t_few).tobytes() == path.evaluate(t_few)[0].tobytes()  # what a move's FK check samples
    assert path.positions(t_few).flags.c_contiguous
    assert np.allclose(q[-1], W[-1], atol=1e-12) and np.abs(qd).max() > 0.1  # it moved, and ends at the goal
