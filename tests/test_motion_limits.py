"""robocfg.motion.limits: limits from the URDF, the robot YAML's overrides and the task's scales."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.config import catalog
from robocfg.config.commands import Limits
from robocfg.errors import ConfigError
from robocfg.motion.limits import limits_from_robot, make_limits

PANDA_V = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]  # pybullet_data panda.urdf <limit velocity>


@pytest.fixture(scope="module")
def panda():
    return load_robot(catalog.find("robots", "panda"))


def _names(robot):
    return robot.arm_joints(robot.config.arms[0])


def test_urdf_velocities_default_acceleration_and_scales(panda):
    lim = limits_from_robot(panda, _names(panda), Limits())
    assert np.allclose(lim.velocity, PANDA_V)
    assert np.allclose(lim.acceleration, 10.0)
    assert lim.jerk is None
    assert lim.lower[3] < lim.upper[3] <= 0  # joint 4 range is non-positive
    half = limits_from_robot(panda, _names(panda), Limits(velocity_scale=0.5, acceleration_scale=0.25,
                                                          acceleration=8.0, jerk=100.0))
    assert np.allclose(half.velocity, np.array(PANDA_V) * 0.5)
    assert np.allclose(half.acceleration, 2.0)
    assert np.allclose(half.jerk, 100.0)


def test_robot_yaml_overrides(tmp_path: Path, panda):
    text = Path(panda.path).read_text().replace(
        "drives:\n", "drives:\n  velocity_limits: {panda_joint1: 1.0}\n  acceleration_limits: {panda_joint2: 3.0}\n")
    f = tmp_path / "panda_limits.yaml"
    f.write_text(text)
    robot = load_robot(f)
    lim = limits_from_robot(robot, _names(robot), Limits(velocity_scale=0.5))
    assert lim.velocity[0] == pytest.approx(0.5)
    assert lim.velocity[1] == pytest.approx(PANDA_V[1] * 0.5)
    assert lim.acceleration[1] == pytest.approx(3.0)
    assert lim.acceleration[0] == pytest.approx(10.0)


def test_missing_urdf_velocity_is_a_config_error(panda):
    joints = dict(panda.urdf.joints)
    j = joints["panda_joint3"]
    joints["panda_joint3"] = SimpleNamespace(**{**j.__dict__, "velocity": 0.0})
    fake = SimpleNamespace(doc=panda.doc, config=panda.config, urdf=SimpleNamespace(joints=joints))
    with pytest.raises(ConfigError) as exc:
        limits_from_robot(fake, _names(panda), Limits())
    text = str(exc.value)
    assert "panda_joint3" in text and "drives.velocity_limits" in text


@pytest.mark.parametrize("key", ["velocity", "acceleration", "jerk"])
@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_make_limits_rejects_non_positive(key, bad):
    kw = {"velocity": [1.0, 1.0], "acceleration": [1.0, 1.0], "jerk": [1.0, 1.0]}
    kw[key] = [1.0, bad]
    with pytest.raises(ValueError, match=f"{key} limit of b"):
        make_limits(["a", "b"], [-1, -1], [1, 1], **kw)


def test_task_scale_zero_is_rejected_by_the_schema():
    from pydantic import ValidationError

    with pytest.raises(ValidationError):
        Limits(velocity_scale=0.0)
    with pytest.raises(ValidationError):
        Limits(acceleration=-1.0)
