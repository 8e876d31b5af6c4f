"""Grip force from the gripper's force limit and the object's mass: pad force by virtual work on
the URDF's finger kinematics, heavy objects rejected before simulating, and the held object
carried no harder than friction holds it."""

import pytest
from _cli import run_main

from robocfg.checks import load_task
from robocfg.checks.grip_force import SAFETY, grip_budget, pad_force
from robocfg.config import catalog
from robocfg.runners.pick_place import run_pick_place


def _robot(name: str):
    task = load_task(catalog.find("tasks", "pick_place"), robot_override=name)
    robot = task.robots[0]
    return robot, robot.config.arm(None)


def test_pad_force_by_virtual_work():
    # Panda: one driven finger joint (N) moves both fingers through the mimic: each pad gets half
    robot, arm = _robot("panda")
    assert pad_force(robot, arm).at(0.05) == pytest.approx(arm.gripper.max_force / 2, rel=1e-3)
    # Robotiq 2F-85: ≈ 10 N per pad per N·m of finger_joint torque (field notes), varying with width
    robot, arm = _robot("ur5e_robotiq_2f85")
    force = pad_force(robot, arm)
    assert 8.0 < force.at(0.03) < force.at(0.07) < 11.0
    assert pad_force(*_robot("kuka_iiwa_suction")) is None  # a cup does not hold by friction


def test_budget_from_mass_and_friction():
    robot, arm = _robot("ur5e_robotiq_2f85")
    force = pad_force(robot, arm)
    light, heavy = (grip_budget(arm, force, m, 1.0, 0.05) for m in (0.1, 0.8))
    assert light.holds and heavy.holds
    assert light.required_force == pytest.approx(0.1 * 9.81 * SAFETY / 2)
    assert light.max_acceleration() > 50.0 > 5.0 > heavy.max_acceleration() > 0.0
    assert not grip_budget(arm, force, 0.8, 0.5, 0.05).holds  # half the friction: it slips


def test_heavy_object_rejected_before_simulating(capsys, monkeypatch):
    """The 2F-140 at its 1 N·m limit squeezes ≈ 4.7 N per pad: 0.5 kg needs 4.9 N with the
    safety factor, so validate and run refuse it (exit 2) naming the forces; 0.1 kg is fine."""
    args = ["pick_place", "--robot", "ur10e_robotiq_2f140", "--set", "pick_place.object.mass=0.5"]
    code, out, err = run_main(["run", "pick-place", *args, "-n", "1", "-q"], capsys, monkeypatch)
    assert code == 2
    assert "pick_place.object.mass: the gripper cannot hold 0.5 kg by friction" in out + err
    assert "Traceback" not in out + err
    code, _, _ = run_main(["run", "pick-place", *args[:3], "--set", "pick_place.object.mass=0.1", "-n", "1", "-q"],
                          capsys, monkeypatch)
    assert code == 0


def test_heavy_object_is_carried_more_gently():
    """0.8 kg in the 2F-85 (≈ 9.3 N per pad) may be accelerated by ≈ 1.8 m/s² only: the carrying
    moves are slowed (transport ≈ 1.35x) and the object is still placed."""
    def transport_time(mass: float) -> float:
        task = load_task(catalog.find("tasks", "pick_place"), robot_override="ur5e_robotiq_2f85",
                         overrides={"pick_place.object.mass": mass})
        report, _ = run_pick_place(task, episodes=1, seed=0)
        e = report.episodes[0]
        assert e.success, (e.failed_phase, e.reason)
        phase = next(p for p in e.phases if p.name == "transport")
        return phase.t_end - phase.t_start

    assert transport_time(0.8) > 1.2 * transport_time(0.1)
