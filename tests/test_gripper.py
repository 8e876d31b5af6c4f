"""Grippers: registry, parallel (measured width, state, grasp), mimic gears, suction."""

from __future__ import annotations

import numpy as np
import pytest
from _sim_helpers import DATA, SHIPPED_ROBOTS, make_task

from robocfg.config.scene import Body
from robocfg.errors import NotFound, RobocfgError
from robocfg.sim.gripper import GRIPPERS, Gripper, ParallelGripper, gripper_class, register
from robocfg.sim.world import World

PANDA = next(f for f in SHIPPED_ROBOTS if f.stem == "panda")


def test_registry_known_unknown_duplicate():
    assert GRIPPERS["parallel"] is ParallelGripper and "suction" in GRIPPERS
    with pytest.raises(NotFound, match=r"suctoin.*did you mean 'suction'.*known: one_jaw, parallel, suction"):
        gripper_class("suctoin")
    with pytest.raises(RobocfgError, match="already registered"):
        register("parallel")(type("Other", (Gripper,), {}))


def test_parallel_width_is_measured_state_and_set_width(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        g = w.robot.arm().gripper
        cfg = g.config
        assert g.width() == pytest.approx(cfg.max_width, abs=0.005) and g.state() == 1.0
        g.set_width(0.04)
        w.step(round(1.0 / w.dt))
        assert g.width() == pytest.approx(0.04, abs=0.004)
        # The measurement follows the fingers, not the command: block one finger's joint by teleporting.
        w.robot.reset_joints(g.joints, [0.01], hold=False)
        w.robot.mimic.sync()
        assert g.width() == pytest.approx(0.02, abs=0.004)
        g.close()
        w.step(round(1.0 / w.dt))
        assert g.width() < 0.003 and g.state() == -1.0


def test_smooth_targets_are_rate_limited(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        g = w.robot.arm().gripper
        g.rate = 1.0  # full travel per second
        g.close()
        w.step(round(0.25 / w.dt))
        assert g._cmd == pytest.approx(0.75, abs=0.02)
        w.step(round(1.0 / w.dt))
        assert g._cmd == 0.0 and g.width() < 0.003


def test_grasp_holds_cube_with_contact_on_both_fingers(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        arm = w.robot.arm()
        g = arm.gripper
        tcp = arm.tcp_pose()
        from robocfg.geometry import matrix_to_quat

        cube = Body(name="cube", shape="box", size=[0.04, 0.04, 0.04], mass=0.1, position=tcp[:3, 3].tolist(),
                    quat_xyzw=matrix_to_quat(arm.ee_pose()[:3, :3]).tolist())
        g.reset(0.55)  # fingers 44 mm apart, then the 40 mm cube appears between them
        w.add_body(cube)
        g.close()
        w.step(round(1.0 / w.dt))  # no support: it must be caught and held
        assert g.is_grasping("cube") and g.is_grasping(w.bodies["cube"])
        assert g.width() == pytest.approx(0.04, abs=0.003)
        assert np.linalg.norm(w.body_pose("cube")[0] - tcp[:3, 3]) < 0.01
        g.set_force(1e-3)  # barely any grip: it slides out
        w.step(round(1.0 / w.dt))
        assert not g.is_grasping("cube")


def test_panda_mimic_tracks_while_moving(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        g, mimic = w.robot.arm().gripper, w.robot.mimic
        assert mimic.followers == ["panda_finger_joint2"] and not w.warnings
        worst = 0.0
        for cmd in (g.close, g.open, g.close):
            cmd()
            for _ in range(round(0.5 / w.dt)):
                w.step()
                worst = max(worst, mimic.max_error())
        assert worst <= 0.01


def test_mimic_with_negative_multiplier_and_offset(tmp_path):
    with World(make_task(tmp_path, DATA / "sim_mimic_robot.yaml")) as w:
        r, g = w.robot, w.robot.arm().gripper
        worst, moved = 0.0, []
        for cmd in (g.close, g.open):
            cmd()
            for _ in range(round(0.6 / w.dt)):
                w.step()
                worst = max(worst, r.mimic.max_error())
            moved.append(r.joint_positions(["finger_left_joint", "finger_right_joint"]))
        assert worst <= 0.01
        assert moved[0][0] == pytest.approx(0.6, abs=0.02)  # closed
        assert moved[0][1] == pytest.approx(-0.6 + 0.1, abs=0.02)  # follower = −1·leader + 0.1
        assert moved[1][1] == pytest.approx(0.1 + 0.1, abs=0.02)
        assert g.width() > 0.05


def test_unenforced_mimic_is_warned(tmp_path):
    urdf = (DATA / "sim_mimic.urdf").read_text().replace('multiplier="-1" offset="0.1"', 'multiplier="0"')
    (tmp_path / "sim_mimic.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text((DATA / "sim_mimic_robot.yaml").read_text())
    with World(make_task(tmp_path, tmp_path / "robot.yaml")) as w:
        assert any("finger_right_joint" in m and "not enforced" in m for m in w.warnings), w.warnings


def _suction_world(tmp_path, mass=0.2):
    cube = {"name": "box", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": mass, "position": [0.15, 0.0, 0.025]}
    return World(make_task(tmp_path, DATA / "sim_suction_robot.yaml", objects=[cube]))


def _lift_to(w, z_cup: float) -> None:
    """Move the lift so the cup face is at height ``z_cup``."""
    arm = w.robot.arm()
    face = w.robot.link_pose("cup")[2, 3]
    arm.command(arm.joint_positions() + (z_cup - face))
    w.step(round(1.5 / w.dt))


def test_suction_attaches_only_on_contact_holds_and_releases(tmp_path):
    with _suction_world(tmp_path) as w:
        g = w.robot.arm().gripper
        g.on()
        w.step(10)
        assert g.attached is None  # cup 0.4 m above the box: nothing to grab
        _lift_to(w, 0.0502)  # 0.2 mm above the box top: within activation_distance
        assert g.is_grasping("box")
        before = w.body_pose("box")[0]
        _lift_to(w, 0.25)
        after = w.body_pose("box")[0]
        assert after[2] - before[2] > 0.15  # lifted with the cup
        assert abs(after[0] - before[0]) < 0.005  # no snap sideways
        assert g.last_load == pytest.approx(0.2 * 9.81, abs=0.3)  # the estimated pull is the weight
        g.off()
        w.step(round(1.0 / w.dt))
        assert not g.is_grasping("box") and w.body_pose("box")[0][2] == pytest.approx(0.025, abs=0.003)


def test_suction_lets_go_above_hold_force(tmp_path):
    with _suction_world(tmp_path, mass=5.0) as w:  # 49 N > hold_force 20 N
        g = w.robot.arm().gripper
        _lift_to(w, 0.0502)
        g.on()
        w.step(2)
        assert g.is_grasping("box")
        _lift_to(w, 0.25)
        assert g.released_by_load and not g.is_grasping("box")
        assert w.body_pose("box")[0][2] < 0.03



def test_state_reads_closed_while_holding_an_object():
    """A gripper closed on the task's 4 cm cube reads closed (−1.0), not open, whatever its gap."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.gripper import run_gripper

    result = run_gripper(load_task(catalog.find("tasks", "gripper")))
    grasp = [m for m in result.moves if m.phase == "grasp"]
    assert grasp and result.hold is not None and result.hold.held
    assert grasp[0].width_end > 0.02 and grasp[0].state_end == -1.0
    assert [m.state_end for m in result.moves if m.phase == "open"] == [1.0]
