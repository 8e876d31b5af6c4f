"""One-jaw gripper (one moving jaw against a fixed one) on the authored sim_onejaw fixture: registry,
measured width, the grasp centre mid-way between the jaw faces, closing on a cube and holding it
by friction through a lift."""

from __future__ import annotations

import numpy as np
import pytest
from _sim_helpers import DATA, make_task

from robocfg.checks import load_robot
from robocfg.config.robot import OneJawGripperConfig
from robocfg.kinematics.frames import ee_pose_from_grasp, grasp_side_shift, top_down_grasps
from robocfg.kinematics.model import KinematicModel
from robocfg.sim.gripper import GRIPPERS, OneJawGripper
from robocfg.sim.world import World

ROBOT = DATA / "sim_onejaw_robot.yaml"
CUBE = 0.05  # m


def test_one_jaw_is_a_registered_kind_and_its_grasp_centre_sits_off_the_axis():
    assert GRIPPERS["one_jaw"] is OneJawGripper
    arm = load_robot(ROBOT).config.arms[0]
    assert isinstance(arm.gripper, OneJawGripperConfig)
    # Fixed jaw face at +0.02 m: a 5 cm object's centre is 2.5 cm short of it, 5 mm on the moving jaw's side.
    assert grasp_side_shift(arm, CUBE) == pytest.approx(-0.005)


def test_width_is_measured_between_the_moving_and_the_fixed_jaw(tmp_path):
    with World(make_task(tmp_path, ROBOT)) as w:
        g = w.robot.arm().gripper
        assert isinstance(g, OneJawGripper)
        assert g.width() == pytest.approx(0.08, abs=0.002) and g.state() == 1.0 and g.fraction() == pytest.approx(1.0, abs=0.01)
        g.set_width(0.03)
        w.step(round(1.0 / w.dt))
        assert g.width() == pytest.approx(0.03, abs=0.003)
        g.close()
        w.step(round(1.0 / w.dt))
        assert g.width() < 0.003 and g.state() == -1.0


def test_closes_on_a_cube_and_holds_it_through_a_lift(tmp_path):
    cube_xyz = np.array([0.5, 0.05, CUBE / 2])
    cube = {"name": "cube", "shape": "box", "size": [CUBE] * 3, "mass": 0.1, "friction": 1.0, "position": cube_xyz.tolist()}
    task = make_task(tmp_path, ROBOT, objects=[cube])
    checked = task.robots[0]
    arm_cfg = checked.config.arms[0]
    model = KinematicModel.from_robot(checked)
    grasp = top_down_grasps(cube_xyz, 0.0, (CUBE, CUBE))[0]
    q_grasp = model.ik(ee_pose_from_grasp(grasp, arm_cfg), frame="ee", time_budget=0.5)
    q_lift = model.ik(ee_pose_from_grasp(grasp, arm_cfg, standoff=0.10), seed_q=q_grasp.q, frame="ee", time_budget=0.5)
    assert q_grasp.converged and q_lift.converged
    with World(task) as w:
        arm = w.robot.arm()
        g = arm.gripper
        names = checked.arm_joints(arm_cfg)
        w.robot.reset_joints(names, q_grasp.q)
        w.step(round(0.3 / w.dt))
        # Open, the fixed jaw stands beside the cube, not in it: the cube has not been pushed.
        assert np.linalg.norm(w.body_pose("cube")[0][:2] - cube_xyz[:2]) < 0.002
        g.close()
        w.step(round(1.0 / w.dt))
        assert g.is_grasping("cube") and g.width() == pytest.approx(CUBE, abs=0.003)
        # Mid-way between the jaw faces: the cube barely moved while the jaw pushed it onto the fixed one.
        assert np.linalg.norm(w.body_pose("cube")[0][:2] - cube_xyz[:2]) < 0.004
        for s in np.linspace(0.0, 1.0, 120):  # lift 10 cm over 1 s, friction alone holds it
            arm.command(q_grasp.q + s * (q_lift.q - q_grasp.q))
            w.step(2)
        w.step(round(0.5 / w.dt))
        z = w.body_pose("cube")[0][2]
        assert z == pytest.approx(CUBE / 2 + 0.10, abs=0.01) and g.is_grasping("cube")
        g.open()
        w.step(round(1.0 / w.dt))
        assert not g.is_grasping("cube") and w.body_pose("cube")[0][2] < CUBE / 2 + 0.005


def test_run_gripper_holds_the_cube_beside_the_fixed_jaw(tmp_path, capsys, monkeypatch):
    from _cli import run_main

    code, out, err = run_main(["run", "gripper", "--robot", str(ROBOT), "-q"], capsys, monkeypatch, tmp_path)
    assert code == 0, err
    assert out.startswith("ok: sim_onejaw one_jaw gripper closed 0.0 mm") and "cube held" in out
