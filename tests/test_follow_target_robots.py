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


def test_moving_target_is_tracked_at_the_same_instant_not_a_step_ahead():
    """Panda on the default circle (0.157 m/s): the TCP is where the target is, not ahead of it.
    It led by two control steps (1.1 mm RMS): the controller's error compared the pose now with
    the target one step later while feeding its velocity forward, and the drives were sent the
    step's end position with its velocity, which PyBullet's motor law turns into one more step of
    lead (``drive_target``)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import run_follow_target

    task = load_task(catalog.find("tasks", "follow_target"), overrides={"follow_target.duration": 2.5})
    res = run_follow_target(task)
    assert res.reached and res.position_error_mm is not None
    assert res.position_error_mm.rms < 0.5  # two steps of lead: 2 × 0.157 m/s × 1/240 s = 1.3 mm


def test_drive_target_keeps_a_pybullet_joint_on_its_ramp():
    """One revolute joint driven along a ramp with ``drive_target``: it stays on the ramp (with the
    ramp's end as the target it runs one physics step ahead)."""
    import pybullet as p
    import pybullet_data

    from robocfg.runners.follow_target_loop import drive_target

    speed, h = 0.5, 1.0 / 240.0
    for n_sub, ahead in ((1, False), (1, True), (4, False)):
        cid = p.connect(p.DIRECT)
        try:
            body = p.loadURDF(pybullet_data.getDataPath() + "/kuka_iiwa/model.urdf", useFixedBase=True, physicsClientId=cid)
            q_end = 0.0
            worst = 0.0
            for _ in range(60):
                q_end += speed * h * n_sub
                target = q_end if ahead else drive_target(np.array([q_end]), np.array([speed]), h * n_sub, n_sub)[0]
                p.setJointMotorControl2(body, 0, p.POSITION_CONTROL, targetPosition=float(target), targetVelocity=speed,
                                        positionGain=0.1, velocityGain=1.0, force=300.0, physicsClientId=cid)
                for _ in range(n_sub):
                    p.stepSimulation(physicsClientId=cid)
                worst = max(worst, abs(p.getJointState(body, 0, physicsClientId=cid)[0] - q_end))
        finally:
            p.disconnect(cid)
            if ahead:
                assert worst > 0.9 * speed * h  # one physics step ahead
            else:
                assert worst < 0.1 * speed * h * n_sub


def test_a_suction_tool_is_not_turned_about_its_axis():
    """The iiwa's home holds its cup pointing down but turned half a turn about the cup's axis from
    the default task's target_euler_deg (written for the Panda's hand). A cup is symmetric about
    its axis (``tool_roll: auto`` = free for suction): the target is tracked from the first
    second, where turning the wrist half a turn at 2 rad/s took 1.6 s and failed the run."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import run_follow_target

    def run(roll: str):
        task = load_task(catalog.find("tasks", "follow_target"), robot_override="kuka_iiwa_suction",
                         overrides={"follow_target.duration": 2.0, "follow_target.tool_roll": roll})
        return run_follow_target(task)

    free, tracked = run("auto"), run("tracked")
    assert free.tool_roll == "free" and tracked.tool_roll == "tracked"
    assert free.reached and free.orientation_error_deg.max < 0.1 and free.position_error_mm.max < 1.0
    assert not tracked.reached and tracked.orientation_error_deg.max > 10.0  # still turning after 1 s
    assert free.samples[0][2] < 1.0 < 170.0 < tracked.samples[0][2]  # the same start, measured both ways


def test_a_scaled_motion_keeps_its_times_unless_the_joints_cannot_keep_up():
    """placement auto on the KR 210: the circle ×3.2 keeps its period (same angular speed; the TCP
    speed cap scales with it) because its joints need ≈ 19 % of their velocity limits for it; with
    the limits cut to a tenth (velocity_scale 0.1) they would need ≈ 190 %, and the times are
    stretched until they need 80 %."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import JOINT_SPEED_SHARE, placed_params

    task = load_task(catalog.find("tasks", "follow_target"), robot_override="kuka_kr210")
    given = task.config.follow_target
    kept, note = placed_params(task, None, given)
    k = kept.motion.radius / given.motion.radius
    assert kept.motion.period == given.motion.period and kept.duration == given.duration
    assert kept.max_speed == pytest.approx(given.max_speed * k)
    assert "times kept (the same angular speed)" in note
    share = float(note.split("the joints at most ")[1].split("%")[0]) / 100
    assert 0.05 < share < JOINT_SPEED_SHARE

    slow = given.model_copy(update={"velocity_scale": 0.1})
    paced, note = placed_params(task, None, slow)
    s = paced.motion.period / given.motion.period
    assert s == pytest.approx(share * 10 / JOINT_SPEED_SHARE, rel=0.05)
    assert paced.duration == pytest.approx(given.duration * s) and f"times x{s:.2f}" in note


def test_the_servo_brakes_as_the_joints_can_instead_of_trading_position():
    """UR5e on the default circle with the angles read on tool0 (``orientation_frame: ee_link``, the
    meaning before the tool frame) and the whole orientation tracked: its home holds the 2F-85 a
    quarter turn about the tool axis from that target, turned at the 2 rad/s cap. The servo stopped
    that turn within a few control periods (20/s gain), the 10 rad/s² joint limits could not follow
    and the QP gave up 36 mm of position for ~0.3 s after settling; braking at
    max_angular_acceleration keeps the position."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import run_follow_target

    task = load_task(catalog.find("tasks", "follow_target"), robot_override="ur5e_robotiq_2f85",
                     overrides={"follow_target.duration": 2.0, "follow_target.orientation_frame": "ee_link",
                                "follow_target.tool_roll": "tracked"})
    res = run_follow_target(task)
    assert res.tool_roll == "tracked" and res.samples[0][2] > 80.0  # it did start a quarter turn away
    assert res.reached and res.position_error_mm.max < 2.0 and res.orientation_error_deg.max < 1.0


def test_the_irb7600_circle_gets_the_largest_scale_ik_reaches():
    """IK reachability along the scale is not monotonic: the IRB 7600 reaches every point of the
    default circle at x0.95 of its reach ratio, not at x1.0 nor x0.9 (where the controller then
    stalled, RMS 50 mm); the 0.05 steps find x0.95 and the run reaches the target."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import placed_params, run_follow_target

    task = load_task(catalog.find("tasks", "follow_target"), robot_override="abb_irb7600")
    _, note = placed_params(task, None, task.config.follow_target)
    assert "x0.95 of 3.60" in note
    report = run_follow_target(task)
    assert report.reached, report.unreachable_reason
    assert report.position_error_mm.rms < 5.0


def test_the_auto_mapping_refuses_a_scale_the_controller_cannot_track(monkeypatch):
    """With the old 0.1 steps the IRB 7600's circle was mapped at x0.9 of the reach ratio: IK reached
    every point, but with the upper arm 0.1 mm from the wrist and through it (−4.1 mm), where the
    controller holds its 20 mm self-collision margin and stalled (RMS 50 mm). The check now asks
    each IK answer for the controller's margins (``controller_margins``): x0.9 is refused, x0.95
    (closest pair 18.5 mm, within the 5 mm reach tolerance of the margin) is kept."""
    import numpy as np

    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.motion import relative
    from robocfg.motion.targets import TargetMotion
    from robocfg.runners.follow_target import POSE_SAMPLES, controller_margins, target_rotation

    task = load_task(catalog.find("tasks", "follow_target"), robot_override="abb_irb7600")
    params = task.config.follow_target
    R, _ = target_rotation(task, None, params)
    target = TargetMotion(params.motion, R)
    poses = [target.pose(float(t)) for t in np.linspace(0.0, params.duration, POSE_SAMPLES)]
    margins = controller_margins(task, None, params)
    monkeypatch.setattr(relative, "SHRINK", (1.0, 0.9))
    ik_only = relative.auto_map(task, None, poses, "circle", "tool")
    assert ik_only is not None and "x0.9 of 3.60" in ik_only.note  # IK alone takes x0.9
    assert relative.auto_map(task, None, poses, "circle", "tool", accept=margins) is None
    monkeypatch.setattr(relative, "SHRINK", (1.0, 0.95, 0.9))
    kept = relative.auto_map(task, None, poses, "circle", "tool", accept=margins)
    assert kept is not None and "x0.95 of 3.60" in kept.note and "keeping the controller's margins" in kept.note


def test_the_default_target_is_the_same_tool_pose_on_a_ur():
    """The default target_euler_deg [180, 0, 0] is read in the tool frame (``orientation_frame:
    tool``): on the UR5e, whose 2F-85 closes along tool0 x, that is the pose its home already holds
    (on tool0 it was a quarter turn away, which the arm turned in its first second)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import run_follow_target

    task = load_task(catalog.find("tasks", "follow_target"), robot_override="ur5e_robotiq_2f85",
                     overrides={"follow_target.duration": 2.0})
    res = run_follow_target(task)
    assert res.tool_roll == "symmetric" and res.samples[0][2] < 5.0  # not a quarter turn away
    assert res.reached and res.orientation_error_deg.max < 0.5


def test_a_parallel_gripper_is_not_turned_half_a_turn(tmp_path):
    """A Panda whose home holds the hand half a turn about the tool axis from the target: its two
    jaws look the same either way (``tool_roll: auto`` = symmetric for a parallel gripper), so the
    half-turned target is tracked from the start; tracked as written, the wrist turns half a turn
    at 2 rad/s and the run is not reached (the drafted UR10 + 2F-85's failure)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.runners.follow_target import run_follow_target

    text = catalog.find("robots", "panda").read_text()
    assert "home: [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]" in text
    robot = tmp_path / "panda_turned.yaml"
    robot.write_text(text.replace("home: [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]",
                                  "home: [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, -2.3566]"))

    def run(roll: str):
        task = load_task(catalog.find("tasks", "follow_target"), robot_override=str(robot),
                         overrides={"follow_target.duration": 2.0, "follow_target.tool_roll": roll})
        return run_follow_target(task)

    sym, tracked = run("auto"), run("tracked")
    assert sym.tool_roll == "symmetric" and any("turned half a turn about the tool axis" in w for w in sym.warnings)
    assert sym.samples[0][2] < 1.0 and sym.reached and sym.orientation_error_deg.max < 0.5
    assert tracked.samples[0][2] > 170.0 and not tracked.reached
