"""Objects sized from their real geometry: primitives, mesh files and URDF objects agree with the
shape PyBullet actually collides with, and the fit check reads that geometry (not ``size``)."""

from pathlib import Path

import numpy as np
import pybullet as pb
import pytest
import yaml

from robocfg.assets.object_shape import object_shape
from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.config.scene import Body
from robocfg.errors import ConfigError
from robocfg.geometry import quat_to_matrix
from robocfg.sim.bodies import spawn_body

BODIES = [
    Body(name="box", shape="box", size=[0.04, 0.06, 0.08], position=[0, 0, 0.5], euler_deg=[0, 0, 30]),
    Body(name="lying", shape="cylinder", size=[0.02, 0.08], position=[0, 0, 0.5], euler_deg=[90, 0, 0]),
    Body(name="ball", shape="sphere", size=[0.03], position=[0, 0, 0.5]),
    Body(name="pill", shape="capsule", size=[0.02, 0.05], position=[0, 0, 0.5], euler_deg=[0, 90, 0]),
    Body(name="duck", shape="mesh", size=[0.8, 0.8, 0.8], mesh="pybullet_data://duck_vhacd.urdf", position=[0, 0, 0.5]),
    Body(name="blob", shape="mesh", size=[1, 1, 1], mesh="pybullet_data://random_urdfs/009/009.urdf", position=[0, 0, 0.5]),
]


@pytest.fixture(scope="module")
def client():
    c = pb.connect(pb.DIRECT)
    pb.setGravity(0, 0, -9.81, physicsClientId=c)
    pb.createMultiBody(0, pb.createCollisionShape(pb.GEOM_PLANE, physicsClientId=c), physicsClientId=c)
    yield c
    pb.disconnect(c)


@pytest.mark.parametrize("body", BODIES, ids=lambda b: b.name)
def test_geometry_matches_what_pybullet_collides_with(body, client):
    """The AABB matches PyBullet's within its collision margin, and dropped on a plane the body's
    lowest point (by our geometry, at the pose it came to rest in) touches the plane."""
    shape = object_shape(body, Path("."))
    bid = spawn_body(client, body, Path("."))
    pos, quat = pb.getBasePositionAndOrientation(bid, physicsClientId=client)
    R = quat_to_matrix(quat)
    lo, hi = (np.array(v) for v in pb.getAABB(bid, physicsClientId=client))
    pts = shape.posed(R) + pos
    if body.shape in ("box", "mesh"):  # Bullet's AABBs of spheres, capsules and turned compounds are looser
        assert np.allclose(pts.min(axis=0), lo, atol=0.006) and np.allclose(pts.max(axis=0), hi, atol=0.006)
    rest = np.array([pos[0], pos[1], shape.below_origin(R)])
    pb.resetBasePositionAndOrientation(bid, rest, quat, physicsClientId=client)
    for _ in range(120):
        pb.stepSimulation(physicsClientId=client)
    pos2, quat2 = pb.getBasePositionAndOrientation(bid, physicsClientId=client)
    lowest = float((shape.posed(quat_to_matrix(quat2)) + pos2)[:, 2].min())  # wherever it rolled to
    assert abs(lowest) < 0.002, lowest
    if body.shape in ("box", "cylinder", "capsule"):  # these rest as placed
        assert abs(pos2[2] - rest[2]) < 0.002, (pos2, rest)
    pb.removeBody(bid, physicsClientId=client)


def test_mesh_size_is_a_scale_and_mass_comes_from_the_urdf():
    one = object_shape(Body(name="d", shape="mesh", size=[1, 1, 1], mesh="pybullet_data://duck_vhacd.urdf"), Path("."))
    half = object_shape(Body(name="d", shape="mesh", size=[0.5, 0.5, 0.5], mesh="pybullet_data://duck_vhacd.urdf"), Path("."))
    assert np.allclose(half.extents(), one.extents() / 2, rtol=1e-6)
    assert 0.05 < one.extents().min() < 0.1  # a duck a few cm across, not "1000 mm"
    assert one.file_mass == pytest.approx(0.1)


def test_lying_cylinder_height_is_its_diameter():
    body = Body(name="c", shape="cylinder", size=[0.02, 0.08], euler_deg=[90, 0, 0])
    shape = object_shape(body, Path("."))
    R = quat_to_matrix(body.quaternion_xyzw())
    assert shape.height(R) == pytest.approx(0.04, abs=1e-6)
    assert shape.min_horizontal_width(R) == pytest.approx(0.04, abs=1e-3)


def _task_with(tmp_path, obj: dict, robot: str = "panda"):
    data = yaml.safe_load(catalog.find("tasks", "pick_place").read_text())
    data["robots"][0]["robot"] = robot
    data["pick_place"]["object"] = {"name": "thing", "position": [0.5, -0.15, 0.05], **obj}
    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_mesh_object_is_not_rejected_by_its_scale(tmp_path):
    task = load_task(_task_with(tmp_path, {"shape": "mesh", "size": [1, 1, 1], "mesh": "pybullet_data://random_urdfs/009/009.urdf"}))
    assert not [w for w in task.warnings if "narrowest" in w.message]


def test_too_wide_box_is_an_error_naming_the_measured_gap(tmp_path):
    with pytest.raises(ConfigError) as exc:
        load_task(_task_with(tmp_path, {"shape": "box", "size": [0.09, 0.1, 0.05]}))
    msg = str(exc.value)
    assert "pick_place.object.size" in msg and "90.0 mm across its narrowest" in msg and "pads measured" in msg


def test_too_wide_mesh_is_a_warning(tmp_path):
    task = load_task(_task_with(tmp_path, {"shape": "mesh", "size": [1, 1, 1], "mesh": "pybullet_data://random_urdfs/000/000.urdf"}))
    assert any("narrowest horizontal side" in w.message and w.severity == "warning" for w in task.warnings)
