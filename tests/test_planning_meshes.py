"""Mesh and URDF bodies (``shape: mesh``) in the planner's collision model and the clutter grasp
filter: a ``pybullet_data`` duck next to the target object is seen as its convex hull (coal), both
lying in the scene and held in the hand, and agrees with PyBullet's own distances."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.collision import EnvShape, robot_geometry
from robocfg.collision.bodies import body_env_shape
from robocfg.config import catalog
from robocfg.config.scene import Body
from robocfg.geometry import pose_to_matrix
from robocfg.kinematics.model import KinematicModel
from robocfg.planning import JointPlanner
from robocfg.planning.checker import CollisionChecker
from robocfg.planning.drive import PlannedDrive, build_planned_drive
from robocfg.sim.world import World

DOWN = np.diag([1.0, -1.0, -1.0])  # TCP z pointing down
TABLE_TOP = 0.1  # clear_table's table top (m)


def _duck(x: float, y: float) -> Body:
    # the duck's lowest point is ≈ 2.7 cm below its body frame at scale 1
    return Body(name="duck", shape="mesh", size=[1.0, 1.0, 1.0], mesh="pybullet_data://duck_vhacd.urdf",
                position=[x, y, TABLE_TOP + 0.03], mass=0.1)


@pytest.fixture(scope="module")
def scene():
    """clear_table's world (table, bin), its red cube as the target and a duck 9 cm beside it,
    the Panda's fingers open."""
    task = load_task(catalog.find("tasks", "clear_table"))
    objects = task.config.pick_place_many.objects
    red = next(o for o in objects if o.name == "red")
    duck = _duck(red.position[0], red.position[1] + 0.09)
    world = World(task)
    for body in (red, duck):
        world.add_body(body)
    arm = world.robot.arm()
    arm.require_gripper().open()
    world.step(240)  # fingers open, objects settled
    kin = KinematicModel.from_robot(world.robot.checked)
    yield SimpleNamespace(world=world, task=task, kin=kin, arm=arm, red=red, duck=duck)
    world.close()


def _ik(kin, pos, seed=None):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = DOWN, pos
    res = kin.ik(T, seed_q=kin.home if seed is None else seed, time_budget=0.2)
    assert res.converged
    return res.q


def test_a_duck_beside_the_target_is_in_the_planners_and_the_filters_model(scene):
    world, kin, red, duck = scene.world, scene.kin, scene.red, scene.duck
    drive = build_planned_drive(world.robot.checked, world, kin, objects=[red, duck])
    assert drive.skipped == [] and "duck" in drive.loose
    drive.refresh_loose(world, ignore=("red",))
    duck_pos = world.body_pose("duck")[0]
    q_in = _ik(kin, duck_pos + np.array([0, 0, 0.01]))  # fingertips straddling the duck's middle
    assert not drive.checker.is_valid(q_in)
    assert any(c.b == "duck" for c in drive.checker.contacts(q_in))
    q_far = _ik(kin, duck_pos + np.array([0, 0, 0.25]))
    assert drive.checker.is_valid(q_far)


def test_the_duck_hull_agrees_with_pybullets_distances(scene):
    """coal's distance to the hull of the duck's convex parts against PyBullet's closest points to
    the parts themselves, over hand poses above and beside the duck: never farther (the hull holds
    the parts) by more than Bullet's hull margins, and wherever PyBullet finds the robot touching
    it the hull is touched too."""
    world, task, kin, arm, duck = scene.world, scene.task, scene.kin, scene.arm, scene.duck
    shape = body_env_shape(duck, pose_to_matrix(*world.body_pose("duck")), task.path.parent)
    checker = CollisionChecker(kin, robot_geometry(world.robot.checked)[0], [shape], margin=0.0)
    centre = world.body_pose("duck")[0]
    pairs = []
    seed = kin.home
    for dz in (0.09, 0.06, 0.04, 0.02):
        for dx, dy in ((0.0, 0.0), (0.03, 0.0), (0.0, 0.05), (-0.05, 0.0), (0.0, -0.06)):
            q = _ik(kin, centre + np.array([dx, dy, dz]), seed)
            seed = q
            world.robot.reset_joints(arm.joints, q)
            pts = world.closest_points(world.robot.body_id, "duck", 0.1)
            pairs.append((checker.clearance(q, scene_only=True), min((p.distance for p in pts), default=0.1)))
    coal_d, bullet_d = np.array(pairs).T
    assert np.any(bullet_d <= 0.0) and np.any(bullet_d > 0.02)  # both touching and clear poses sampled
    assert np.all(coal_d <= bullet_d + 0.004), pairs
    assert np.all(coal_d[bullet_d <= 0.0] <= 0.0), pairs


def _at(pos) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = pos
    return T


def test_a_held_duck_is_its_hull_not_a_bounding_sphere(scene):
    """A duck held between the fingertips (attached through ``PlannedDrive.attach``) collides
    with a plate 5 mm past its far side only where its hull reaches: a plate 10 cm away is clear
    (a bounding sphere of the scale box, r = 0.87 m, hit it)."""
    world, task, kin, duck = scene.world, scene.task, scene.kin, scene.duck
    T_ee = kin.fk(kin.home, "ee")
    held = _at([0.0, 0.0, 0.14])  # the duck's body frame 14 cm along the flange's z
    reach = float(np.max(body_env_shape(duck, held, task.path.parent).vertices @ T_ee[:3, :3].T[2]))
    centre = (T_ee @ held)[:3, 3]
    links = robot_geometry(world.robot.checked)[0]
    for past, free in ((-0.01, False), (0.10, True)):  # plate 1 cm into / 10 cm past the duck's far side
        # a 2 cm plate across the flange's z axis, its near face ``past`` beyond the duck's far side
        plate = _at(centre + T_ee[:3, 2] * (reach + past + 0.01))
        plate[:3, :3] = T_ee[:3, :3]
        checker = CollisionChecker(kin, links, [EnvShape("plate", "box", (0.3, 0.3, 0.02), plate)], margin=0.0)
        assert checker.is_valid(kin.home)  # the hand alone is clear of both
        drive = PlannedDrive(JointPlanner(checker, kin.lower, kin.upper), kin, kin.ee_link, [], task.path.parent)
        drive.attach("duck", duck, held)
        assert checker.is_valid(kin.home) is free
        if not free:
            assert any(c.a == "held object 'duck'" and c.b == "plate" for c in checker.contacts(kin.home))


def _clear_table_with_a_duck(tmp_path, position) -> object:
    """clear_table with its red box and a duck (scale 1) at ``position`` (the bin holds two of
    the duck's 69 mm footprint)."""
    import yaml

    task = load_task(catalog.find("tasks", "clear_table"))
    data = yaml.safe_load(task.path.read_text())
    objects = data["pick_place_many"]["objects"]
    duck = {"name": "duck", "shape": "mesh", "mesh": "pybullet_data://duck_vhacd.urdf", "size": [1.0, 1.0, 1.0],
            "position": list(position), "region": {"xy_range": [0.004, 0.004]}}
    data["pick_place_many"]["objects"] = [o for o in objects if o["name"] == "red"] + [duck]
    path = tmp_path / "clear_duck.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_a_duck_is_checked_by_its_geometry_not_by_its_scale(tmp_path):
    """``size`` of a mesh is a scale: a duck at scale 1 (≈ 8 × 8 × 6 cm) on the table is not
    "inside" the bin 0.45 m away (its scale read as a 1 m box was), and one standing in the
    bin's wall still is."""
    from robocfg.errors import ConfigError

    task = load_task(_clear_table_with_a_duck(tmp_path, [0.45, -0.4, TABLE_TOP + 0.03]))
    assert [o.name for o in task.config.pick_place_many.objects][-1] == "duck"
    with pytest.raises(ConfigError) as exc:
        load_task(_clear_table_with_a_duck(tmp_path, [0.5, 0.05, TABLE_TOP + 0.03]))  # on bin/wall_-y
    assert any("'duck'" in p.message and "bin/wall_-y" in p.message for p in exc.value.problems)
