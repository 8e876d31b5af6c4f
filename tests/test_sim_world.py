"""World from a task YAML: loading every shipped robot, holding home, bodies, mounts, bad input."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from _sim_helpers import DATA, PANDA, SHIPPED_ROBOTS, make_task

from robocfg.config.scene import Body
from robocfg.errors import ConfigError, PhysicsDiverged
from robocfg.geometry import quat_to_matrix
from robocfg.sim.world import World


@pytest.mark.parametrize("robot_file", SHIPPED_ROBOTS, ids=lambda f: f.stem)
def test_smoke_every_shipped_robot(tmp_path, robot_file):
    """Load, home, hold 1 s still; self-collisions at home reported; open/close changes the width."""
    task = make_task(tmp_path, robot_file)
    with World(task) as w:
        r = w.robot
        for arm in r.arms.values():
            assert np.allclose(arm.joint_positions(), arm.home, atol=1e-6)
        q0, base0 = r.joint_positions(), r.base_pose()
        w.step(round(1.0 / w.dt))
        for arm in r.arms.values():
            drift = np.abs(arm.joint_positions() - arm.home).max()
            assert drift < 0.01, f"{arm.config.name}: drift {drift:.4f} rad"
        assert np.abs(r.joint_positions() - q0).max() < 0.01
        assert np.allclose(r.base_pose(), base0, atol=1e-6)
        collisions = r.self_collisions()  # reported, not failed: print them for the log
        print(f"{r.name}: self-collisions at home: {collisions}")
        assert all(depth <= 0 for _, _, depth in collisions)
        for arm in r.arms.values():
            g = arm.gripper
            if g is None or g.type_name != "parallel":
                continue
            cfg = g.config
            g.close()
            w.step(round(1.5 / w.dt))
            closed = g.width()
            g.open()
            w.step(round(1.5 / w.dt))
            opened = g.width()
            assert opened - closed >= 0.8 * (cfg.max_width - cfg.min_width), (closed, opened)
            assert g.state() == 1.0


def test_tcp_pose_matches_urdf_fk_and_mount(tmp_path):
    mount = {"position": [0.2, -0.1, 0.3], "euler_deg": [0.0, 0.0, 30.0]}
    task = make_task(tmp_path, PANDA, mount=mount)
    with World(task) as w:
        arm = w.robot.arm()
        T_mount = np.eye(4)
        T_mount[:3, :3] = quat_to_matrix(task.config.robots[0].quaternion_xyzw())
        T_mount[:3, 3] = mount["position"]
        assert np.allclose(w.robot.base_pose(), T_mount, atol=1e-6)
        q = {n: v for n, v in zip(arm.joints, arm.home, strict=True)}
        urdf = w.robot.checked.urdf
        T_ee = T_mount @ urdf.link_pose(arm.config.ee_link, q)
        assert np.allclose(arm.ee_pose(), T_ee, atol=1e-5)
        tcp = arm.tcp_pose()
        axis = "xyz".index(arm.config.ee_axis)
        assert np.allclose(tcp[:3, 3], T_ee[:3, 3] + arm.config.tcp_offset * T_ee[:3, axis], atol=1e-5)


def test_command_positions_moves_the_joint(tmp_path):
    task = make_task(tmp_path, PANDA)
    with World(task) as w:
        arm = w.robot.arm()
        target = arm.home.copy()
        target[0] += 0.3
        arm.command(target)
        w.step(round(2.0 / w.dt))
        assert abs(arm.joint_positions()[0] - target[0]) < 0.01
        w.robot.reset_joints(arm.joints[:1], [-0.2])
        w.step(round(0.5 / w.dt))
        assert abs(arm.joint_positions()[0] + 0.2) < 0.01  # teleported and held there


def test_bodies_add_remove_pose_and_two_worlds(tmp_path):
    cube = {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.2, "position": [0.6, 0.3, 0.2]}
    task = make_task(tmp_path, PANDA, objects=[cube])
    with World(task) as a, World(task) as b:
        assert a.client != b.client
        assert {"ground", "cube"} <= set(a.bodies)
        a.step(round(1.0 / a.dt))
        pos, _ = a.body_pose("cube")
        assert abs(pos[2] - 0.025) < 0.002  # fell and rests on the ground
        assert b.body_pose("cube")[0][2] == pytest.approx(0.2)  # the other world did not move
        ball = Body(name="ball", shape="sphere", size=[0.03], mass=0.1, position=[0.5, -0.3, 0.03])
        bid = a.add_body(ball)
        assert a.bodies["ball"] == bid and np.allclose(a.body_pose(bid)[0], [0.5, -0.3, 0.03])
        for shape, size in (("cylinder", [0.02, 0.1]), ("capsule", [0.02, 0.1])):
            a.add_body(Body(name=shape, shape=shape, size=size, position=[0.5, 0.5, 0.2]))
        a.step(10)
        a.remove_body("ball")
        assert "ball" not in a.bodies
        with pytest.raises(Exception, match="ball"):
            a.body_pose("ball")


def test_scene_table_pedestal_obstacle(tmp_path):
    extra = {"scene": {"ground": True, "table": {"position": [0.6, 0.0, 0.4], "size": [0.6, 0.8, 0.04]},
                       "pedestal": {"position": [0.0, 0.0, 0.3], "radius": 0.12, "height": 0.3},
                       "obstacles": [{"name": "wall", "shape": "box", "size": [0.05, 0.4, 0.3],
                                      "position": [0.6, 0.0, 0.55]}]}}
    task = make_task(tmp_path, PANDA, mount={"position": [0.0, 0.0, 0.3]}, extra=extra)
    with World(task) as w:
        lo, hi = p.getAABB(w.bodies["table"], physicsClientId=w.client)
        assert hi[2] == pytest.approx(0.4, abs=1e-3)
        lo, hi = p.getAABB(w.bodies["pedestal"], physicsClientId=w.client)
        assert hi[2] == pytest.approx(0.3, abs=1e-3) and lo[2] == pytest.approx(0.0, abs=1e-3)
        q0 = w.robot.joint_positions()
        w.step(120)
        assert np.abs(w.robot.joint_positions() - q0).max() < 0.01
        assert w.body_pose("wall")[0][2] == pytest.approx(0.55)  # static


def test_object_inside_robot_warns(tmp_path):
    task = make_task(tmp_path, PANDA)
    with World(task) as w:
        tcp = w.robot.arm().ee_pose()[:3, 3]
        w.add_body(Body(name="intruder", shape="box", size=[0.06, 0.06, 0.06], mass=0.1, position=tcp.tolist()))
        assert any("intruder" in m and "inside robot" in m for m in w.warnings), w.warnings


def test_divergence_raises(tmp_path):
    cube = {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.2, "position": [0.6, 0.3, 0.2]}
    task = make_task(tmp_path, PANDA, objects=[cube])
    with World(task) as w:
        w.step(5)
        p.resetBaseVelocity(w.bodies["cube"], [1e4, 0, 0], physicsClientId=w.client)
        with pytest.raises(PhysicsDiverged, match=r"physics diverged at t = 0\.050 s.*cube"):
            w.step(w.check_every)  # checked every 50 ms of simulated time: at step 12
    with World(task) as w:
        arm = w.robot.arm()
        p.resetJointState(w.robot.body_id, w.robot.joint_index[arm.joints[0]], 0.0, float("nan"),
                          physicsClientId=w.client)
        with pytest.raises(PhysicsDiverged, match="joint"):
            w.step(w.check_every)


def test_unloadable_mesh_is_named(tmp_path):
    (tmp_path / "broken.stl").write_bytes(b"this is not an STL file\x00\x01\x02")
    urdf = (DATA / "sim_suction.urdf").read_text().replace(
        '<collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision>',
        '<collision><geometry><mesh filename="broken.stl"/></geometry></collision>')
    (tmp_path / "robot.urdf").write_text(urdf)
    robot_yaml = (DATA / "sim_suction_robot.yaml").read_text().replace("urdf: sim_suction.urdf", "urdf: robot.urdf")
    (tmp_path / "robot.yaml").write_text(robot_yaml)
    task = make_task(tmp_path, tmp_path / "robot.yaml")
    with pytest.raises(ConfigError) as info:
        World(task)
    msg = str(info.value)
    assert "broken.stl" in msg and "carriage" in msg and "robot.yaml" in msg


def test_missing_inertial_gets_link_mass(tmp_path):
    urdf = (DATA / "sim_suction.urdf").read_text().replace(
        '<inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>', "")
    (tmp_path / "robot.urdf").write_text(urdf)
    robot_yaml = (DATA / "sim_suction_robot.yaml").read_text().replace("urdf: sim_suction.urdf", "urdf: robot.urdf")
    robot_yaml = robot_yaml.replace("  solver_iterations: 100", "  solver_iterations: 100\n  link_masses: {carriage: 0.3}")
    (tmp_path / "robot.yaml").write_text(robot_yaml)
    task = make_task(tmp_path, tmp_path / "robot.yaml")
    with World(task) as w:
        r = w.robot
        assert p.getDynamicsInfo(r.body_id, r.link("carriage"), physicsClientId=w.client)[0] == pytest.approx(0.3)


def test_a_body_spawned_again_reuses_its_shapes(tmp_path):
    """PyBullet never frees a created shape: the object re-spawned every episode must reuse its
    collision and visual shapes (one cache entry per distinct shape, size, mesh and colour)."""
    task = make_task(tmp_path, PANDA)
    with World(task) as w:
        ball = Body(name="ball", shape="sphere", size=[0.03], mass=0.1, position=[0.5, -0.3, 0.03])
        first = w.shape_cache.shapes(w.client, ball, tmp_path)
        for _ in range(5):
            w.add_body(ball)
            w.step(2)
            w.remove_body("ball")
        assert w.shape_cache.shapes(w.client, ball, tmp_path) == first and len(w.shape_cache) == 1
        w.add_body(ball.model_copy(update={"color": [0.1, 0.2, 0.3, 1.0]}))
        w.add_body(ball.model_copy(update={"name": "big", "size": [0.05]}))
        assert len(w.shape_cache) == 3
        assert np.allclose(w.body_pose("big")[0], [0.5, -0.3, 0.03])
