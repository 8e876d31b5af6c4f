"""robocfg.config.types: pose orientation conventions."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from robocfg.config.types import Pose
from robocfg.geometry import euler_deg_to_quat_xyzw


def test_quaternion_orders_agree():
    q = euler_deg_to_quat_xyzw([10.0, 20.0, 30.0])
    a = Pose(quat_xyzw=list(q)).quaternion_xyzw()
    b = Pose(quat_wxyz=[q[3], q[0], q[1], q[2]]).quaternion_xyzw()
    c = Pose(euler_deg=[10.0, 20.0, 30.0]).quaternion_xyzw()
    assert np.allclose(a, b) and np.allclose(a, c)
    assert Pose().quaternion_xyzw() == (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("key", ["orientation", "quat", "quaternion", "rotation"])
def test_bare_four_vector_is_rejected(key):
    with pytest.raises(ValidationError, match="ambiguous"):
        Pose.model_validate({key: [0, 0, 0, 1]})


def test_orientation_rules():
    with pytest.raises(ValidationError, match="one orientation"):
        Pose(euler_deg=[0, 0, 0], quat_xyzw=[0, 0, 0, 1])
    with pytest.raises(ValidationError, match="unit quaternion"):
        Pose(quat_wxyz=[2, 0, 0, 0])
    with pytest.raises(ValidationError):
        Pose(position=[0, 0])
    with pytest.raises(ValidationError):
        Pose(position=[0, 0, float("nan")])
