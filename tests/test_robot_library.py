"""Robots added by YAML alone: an industrial arm on a pedestal, an arm + suction attachment, a
dual-arm cell. One pick-place episode each really moves the object onto the place point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from robocfg.checks import load_robot, load_task
from robocfg.config import catalog
from robocfg.engine.options import EpisodeObserver
from robocfg.runners.pick_place import run_pick_place


class _ArmWatch(EpisodeObserver):
    """Stands in for a Recorder (``record=``) to read the world at the end of the episode."""

    def __init__(self, world):
        self.world, self.max_dev, self.at_end = world, {}, {}

    def maybe_capture(self) -> None:
        robot = self.world.robot
        for name, arm in robot.arms.items():
            dev = float(np.abs(arm.joint_positions() - arm.home).max())
            self.max_dev[name] = max(self.max_dev.get(name, 0.0), dev)
        for name, q in robot.config.locked_joints.items():  # e.g. a torso lift held at its home
            dev = abs(float(robot.joint_positions([name])[0]) - q)
            self.max_dev[name] = max(self.max_dev.get(name, 0.0), dev)

    def save(self) -> None:
        self.at_end = {n: a.joint_positions() for n, a in self.world.robot.arms.items()}


def _placed(report, task) -> None:
    e = report.episodes[0]
    assert e.success, (e.failed_phase, e.reason)
    final = np.asarray(e.object_final)
    assert np.linalg.norm(final[:2] - np.asarray(e.place_target)) <= task.config.pick_place.success_tolerance


@pytest.mark.parametrize(("task_name", "robot"), [("pick_place", "dual_panda"), ("pick_place_dual_arm_lift", None)],
                         ids=["dual_panda", "dual_arm_lift"])
@pytest.mark.parametrize("arm", ["left", "right"])
def test_dual_arm_cell_picks_with_either_arm_while_the_other_holds(arm, task_name, robot):
    """The idle arm and any locked joint (dual_arm_lift's torso lift) stay where they are."""
    task = load_task(catalog.find("tasks", task_name), robot_override=robot)
    watches: list[_ArmWatch] = []

    def record(world):
        watches.append(_ArmWatch(world))
        return watches[-1]

    report, _ = run_pick_place(task, episodes=1, arm=arm, record=record)
    _placed(report, task)
    assert report.arm == arm
    other = "right" if arm == "left" else "left"
    w = watches[0]
    assert w.max_dev[other] < 1e-3, f"the idle arm moved {w.max_dev[other]:.2e} rad"
    assert w.max_dev[arm] > 0.3  # the working arm really moved
    for name in task.robots[0].config.locked_joints:
        assert w.max_dev[name] < 1e-3, f"locked joint {name} moved {w.max_dev[name]:.2e}"


def test_industrial_arm_on_a_yawed_pedestal_moves_a_heavy_box():
    task = load_task(catalog.find("tasks", "pick_place_kuka_kr210"))
    mount = task.config.robots[0]
    assert task.config.scene.pedestal is not None and mount.position[2] == task.config.scene.pedestal.position[2]
    assert mount.euler_deg[2] != 0.0  # yawed
    obj = task.config.pick_place.object
    assert obj.mass >= 5.0 and min(obj.size) >= 0.3
    robot = task.robots[0].config
    assert robot.arms[0].gripper.hold_force > 3 * obj.mass * 9.81  # sized for the box
    report, _ = run_pick_place(task, episodes=1)
    _placed(report, task)
    e = report.episodes[0]
    assert e.lift_rise > 0.5 * task.config.pick_place.lift_height
    # the box moved a long way: pick and place are 1.4 m apart
    assert math.dist(e.object_start[:2], e.place_target) > 1.0


def test_arm_with_an_attached_suction_cup_runs_the_default_task():
    robot = load_robot(catalog.find("robots", "kuka_iiwa_suction"))
    assert "suction_cup" in robot.urdf.links and "lbr_iiwa_link_7" in robot.urdf.links  # composed
    task = load_task(catalog.find("tasks", "pick_place"), robot_override="kuka_iiwa_suction")
    report, _ = run_pick_place(task, episodes=1, seed=3)
    _placed(report, task)


def test_authored_kr210_urdf_has_data_sheet_kinematics():
    """Reach 2.7 m (A1 axis to wrist centre, arm stretched horizontally), A2 at 0.675 m."""
    robot = load_robot(catalog.find("robots", "kuka_kr210"))
    urdf = robot.urdf
    # stretched out horizontally: q2 = 90° (upper arm forward), q3 = −90° (forearm in line)
    q = {"joint_a2": math.pi / 2, "joint_a3": -math.pi / 2}
    a2 = urdf.link_pose("link_2", q)[:3, 3]
    wrist = urdf.link_pose("link_5", q)[:3, 3]
    assert a2[2] == pytest.approx(0.675) and a2[0] == pytest.approx(0.35)
    assert wrist[0] == pytest.approx(2.70, abs=1e-6)
    masses = [ln.mass for ln in urdf.links.values() if ln.mass]
    assert 900 < sum(masses) < 1200  # the data sheet's ≈ 1.07 t


def test_grasp_choice_avoids_a_far_ik_branch(monkeypatch):
    """Episode 26 (seed 0) on the right arm: the grasp with the smaller wrist turn has its
    pre-grasp IK answer on a flipped-shoulder branch (|Δq| ≈ 3 rad, 4.3 s of motion, past the
    4 s timeout); the runner now takes the other top-down grasp (|Δq| ≈ 1.7 rad)."""
    import robocfg.runners.pick_place as pp

    task = load_task(catalog.find("tasks", "pick_place"), robot_override="dual_panda")
    all_setups = pp.episode_setups(task.config.pick_place, 0, 27)
    monkeypatch.setattr(pp, "episode_setups", lambda params, seed, episodes: [all_setups[26]])
    report, _ = run_pick_place(task, episodes=1, arm="right")
    _placed(report, task)
    pre = report.episodes[0].phases[0]
    assert pre.name == "pre_grasp" and pre.t_end - pre.t_start < 4.0


# ---- robots authored from published data (UR10e + 2F-140, ABB IRB 7600, NEURA MAiRA 7M) ----------


def test_authored_ur10e_follows_the_published_dh_table():
    """Zero pose: tool0 at (−a2 − a3, d4 + d6, d1 − d5) = (1.18425, 0.2907, 0.06085) m; the
    tutorial's home points the gripper straight down."""
    robot = load_robot(catalog.find("robots", "ur10e_robotiq_2f140"))
    urdf = robot.urdf
    np.testing.assert_allclose(urdf.link_pose("tool0", {})[:3, 3], [1.18425, 0.2907, 0.06085], atol=1e-9)
    arm = robot.config.arm()
    home = urdf.link_pose("tool0", dict(zip(arm.joints, arm.home, strict=True)))
    assert home[:3, 2] @ [0.0, 0.0, -1.0] > 0.999  # approach axis down
    masses = [ln.mass for ln in urdf.links.values() if ln.mass]
    assert 33.0 < sum(masses) < 36.0  # UR10e 33.5 kg + 2F-140 ≈ 1 kg


def test_tutorial_trajectory_on_the_ur10e_takes_the_minimal_time_of_its_limits():
    """home → reach-out → home under 0.5 rad/s² (stopping at each waypoint): the elbow's 0.77 rad
    is the longest move, a bang-bang profile of 2·√(0.77 / 0.5) = 2.48 s per leg."""
    from robocfg.runners.trajectory import run_trajectory

    res = run_trajectory(load_task(catalog.find("tasks", "trajectory_ur10e")))
    assert res.success
    assert res.duration == pytest.approx(2 * 2 * math.sqrt(0.77 / 0.5), rel=0.01)
    assert res.tracking is not None


def test_tutorial_follow_target_on_the_ur10e_keeps_clear_of_the_obstacle_cube():
    from robocfg.runners.follow_target import run_follow_target

    res = run_follow_target(load_task(catalog.find("tasks", "follow_target_ur10e")))
    assert res.reached and res.contacts == 0
    assert res.min_clearance_mm is not None and res.min_clearance_mm > 15.0  # 20 mm margin, soft


def test_2f140_strokes_140_mm_with_fingers_parallel():
    """Close the 2F-140 in steps: the measured pad gap runs from 140 mm to ≈ 0 and each pad keeps
    its orientation relative to the gripper body (the four-bar's mimic joints hold)."""
    from robocfg.sim.world import World

    task = load_task(catalog.find("tasks", "gripper_ur10e"))
    with World(task) as world:
        robot, g = world.robot, world.robot.arm().gripper
        widths, tilt = [], 0.0
        for s in np.linspace(1.0, 0.0, 8):
            g.set_fraction(s)
            world.step(round(0.4 / world.dt))
            widths.append(g.width())
            base = robot.link_pose("robotiq_2f140_base_link")[:3, :3]
            for pad in ("left_inner_finger_pad", "right_inner_finger_pad"):
                rel = base.T @ robot.link_pose(pad)[:3, :3]
                tilt = max(tilt, math.acos(np.clip((np.trace(rel) - 1) / 2, -1, 1)))
    assert widths[0] == pytest.approx(0.140, abs=1e-3)
    assert widths[-1] < 0.002
    assert np.all(np.diff(widths) < 0)
    assert tilt < 0.01, f"a pad turned {tilt:.4f} rad"


def test_authored_irb7600_has_product_spec_kinematics():
    """Calibration pose: A2 at (0.41, 0.78) m; wrist centre 3.50 m out (0.41 + 1.075 + 2.012) at the
    A4 height 0.78 + 1.075 + 0.165; tilted forward onto the horizontal it reaches 3.497 m."""
    robot = load_robot(catalog.find("robots", "abb_irb7600"))
    urdf = robot.urdf
    np.testing.assert_allclose(urdf.link_pose("link_2", {})[:3, 3], [0.41, 0.0, 0.78], atol=1e-9)
    np.testing.assert_allclose(urdf.link_pose("link_5", {})[:3, 3], [2.422, 0.0, 2.02], atol=1e-9)
    wc = urdf.link_pose("link_5", {"joint_2": math.pi / 2, "joint_3": -math.pi / 2})[:3, 3]
    assert wc[0] == pytest.approx(0.41 + 1.075 + 2.012) and wc[2] == pytest.approx(0.78 + 0.165)
    masses = [ln.mass for ln in urdf.links.values() if ln.mass]
    assert 2400 < sum(masses) < 2500  # the data sheet's 2.45 t, tool included


def test_authored_maira7m_has_seven_axes_with_the_published_ranges():
    robot = load_robot(catalog.find("robots", "neura_maira7m"))
    arm = robot.config.arm()
    limits = [robot.urdf.joints[j].upper for j in arm.joints]
    np.testing.assert_allclose(np.degrees(limits), [180, 120, 180, 150, 180, 145, 180], atol=1e-4)
    stretched = robot.urdf.link_pose("flange", {"joint_2": math.pi / 2})[:3, 3]
    assert stretched[0] == pytest.approx(1.0)  # reach from the shoulder axis to the flange


class _SlipWatch(EpisodeObserver):
    """A ``record=`` stand-in that follows the carried object in the suction-cup frame: slip is
    how far it moves there from where it sat at the start of the lift (m); ``carried`` is the
    path length (m) the object travels during the transport phase."""

    def __init__(self, world, obj: str, cup: str):
        self.world, self.obj, self.cup = world, obj, cup
        self.phase, self.ref, self.slip, self.carried, self.last = "", None, 0.0, 0.0, None

    def set_phase(self, name: str) -> None:
        self.phase = name

    def maybe_capture(self) -> None:
        if self.phase not in ("lift", "transport", "lower"):
            return
        T = self.world.robot.link_pose(self.cup)
        pos = self.world.body_pose(self.obj)[0]
        rel = T[:3, :3].T @ (pos - T[:3, 3])
        if self.ref is None:
            self.ref = rel
        self.slip = max(self.slip, float(np.linalg.norm(rel - self.ref)))
        if self.phase == "transport" and self.last is not None:
            self.carried += float(np.linalg.norm(pos - self.last))
        self.last = pos


@pytest.mark.parametrize("robot", ["kuka_kr210", "abb_irb7600", "neura_maira7m"])
def test_multi_brand_cell_suction_holds_the_5kg_panel_at_full_speed(robot):
    """The cell task with each brand: the 5 kg panel is carried more than 1 m at speed_scale 1 and
    slips at most 5 mm in the cup frame; the robot sits on the 2.51 m pedestal yawed 145°."""
    task = load_task(catalog.find("tasks", "pick_place_cell"), robot_override=robot)
    cfg = task.config
    assert cfg.robots[0].position[2] == pytest.approx(2.51) and cfg.robots[0].euler_deg[2] == pytest.approx(145.0)
    assert cfg.pick_place.object.mass == 5.0 and cfg.pick_place.speed_scale == 1.0
    watches: list[_SlipWatch] = []

    def record(world):
        watches.append(_SlipWatch(world, cfg.pick_place.object.name, task.robots[0].config.arms[0].gripper.link))
        return watches[-1]

    report, _ = run_pick_place(task, episodes=1, record=record)
    _placed(report, task)
    w = watches[0]
    assert w.carried > 1.0, f"carried only {w.carried:.2f} m"
    assert w.slip <= 0.005, f"slipped {w.slip * 1000:.1f} mm"


@pytest.mark.parametrize(("task_name", "robot"), [("pick_place_ur10e", None)])
def test_authored_robot_runs_its_own_pick_place(task_name, robot):
    task = load_task(catalog.find("tasks", task_name), robot_override=robot)
    report, _ = run_pick_place(task, episodes=1, seed=1)
    _placed(report, task)


# ---- a dual-arm robot on a torso lift ---------------------------------------------------------


def _lift_in_the_left_arm(tmp_path, keep_locked: bool = False):
    """The other robot-YAML choice: lift_joint first in the left arm's chain (IK moves it)."""
    import yaml

    src = catalog.find("robots", "dual_arm_lift")
    data = yaml.safe_load(src.read_text())
    data["urdf"] = str(src.parent / data["urdf"])
    left = data["arms"][0]
    left["joints"] = ["lift_joint", *left["joints"]]
    left["home"] = [0.15, *left["home"]]
    left["home_std"] = [0.01, *left["home_std"]]
    left["base_link"] = "base_link"
    if not keep_locked:
        del data["locked_joints"]
    path = tmp_path / "lift_ik.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_dual_arm_lift_is_locked_at_its_home_height():
    robot = load_robot(catalog.find("robots", "dual_arm_lift"))
    assert robot.config.locked_joints == {"lift_joint": 0.15}
    assert robot.urdf.joints["lift_joint"].type == "prismatic"


def test_dual_arm_lift_as_an_ik_joint_reaches_higher(tmp_path):
    """With the lift in the left arm's chain IK uses it: a TCP target 0.5 m above the locked arm's
    reach is solved by raising the lift, and FK of the answer lands on the target."""
    from robocfg.kinematics.ik.lm import LMSolver
    from robocfg.kinematics.model import KinematicModel

    robot = load_robot(_lift_in_the_left_arm(tmp_path))
    model = KinematicModel.from_robot(robot, arm="left")
    assert model.nq == 8
    home = np.asarray(robot.config.arm("left").home)
    target = model.fk(home, "tcp")
    target[2, 3] += 0.4  # beyond the locked arm: its home TCP is already near full height
    res = LMSolver(model).solve(target, home, time_budget=0.5)
    assert res.converged, (res.pos_err, res.rot_err)
    assert res.q[0] > 0.3  # the lift rose
    np.testing.assert_allclose(model.fk(res.q, "tcp")[:3, 3], target[:3, 3], atol=1e-4)
    locked = KinematicModel.from_robot(load_robot(catalog.find("robots", "dual_arm_lift")), arm="left")
    assert locked.nq == 7
    assert not LMSolver(locked).solve(target, home[1:], time_budget=0.2).converged


def test_a_locked_joint_that_an_arm_drives_is_an_error(tmp_path):
    from robocfg.errors import ConfigError

    with pytest.raises(ConfigError) as exc:
        load_robot(_lift_in_the_left_arm(tmp_path, keep_locked=True))
    assert "locked_joints.lift_joint: 'lift_joint' is an arm or gripper joint" in str(exc.value)
