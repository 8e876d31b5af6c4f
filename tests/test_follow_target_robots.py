"""The default follow-target task on the built-in robots beyond the desk arms: the reactive
controller's model holds the joints the arm does not move where the simulator holds them."""

from __future__ import annotations

import numpy as np
import pytest

from robocfg.api import load_robot
from robocfg.kinematics.model import KinematicModel
from robocfg.motion.reactive import ReactiveController, ReactiveSettings
from robocfg.motion.reactive.setup import arm_spec

DT = 1.0 / 240.0


@pytest.mark.parametrize("arm", ["left", "right"])
def test_controller_model_holds_the_locked_lift_and_the_other_arm(arm):
    """dual_arm_lift locks its torso lift at 0.15 m (``locked_joints``): the controller's TCP at home
    is the kinematic model's (it was 150 mm low with the lift read as 0), and the other arm is at
    its home pose in the controller's collision model."""
    robot = load_robot("dual_arm_lift")
    spec = arm_spec(robot, robot.urdf_path, np.eye(4), arm)
    assert spec.other_joints["lift_joint"] == pytest.approx(0.15)
    other = next(a for a in robot.config.arms if a.name != arm)
    for name, q in zip(robot.arm_joints(other), other.home, strict=True):
        assert spec.other_joints[name] == pytest.approx(q)
    assert not set(spec.other_joints) & set(spec.joint_names)
    ctrl = ReactiveController(spec, [], ReactiveSettings(dt=DT))
    home = np.asarray(robot.config.arm(arm).home, float)
    model = KinematicModel.from_robot(robot, arm=arm)
    expected = model.fk(home, "tcp")
    assert np.linalg.norm(ctrl.tcp_pose(home)[:3, 3] - expected[:3, 3]) < 1e-6
