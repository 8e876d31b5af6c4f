"""Simulated RGB-D camera: back-projection lands on the known geometry; frustum checks and warnings."""

import numpy as np
import pybullet as p
import pytest

from robocfg.config.commands import Camera, GraspParams
from robocfg.grasp.cloud import Cloud, crop, estimate_normals, from_rgbd, voxel_downsample
from robocfg.grasp.perception import camera_warnings
from robocfg.sim.camera import backproject, capture, matrices, sees_box

HALF = np.array([0.05, 0.04, 0.03])
CENTER = np.array([0.5, 0.0, 0.03])


@pytest.fixture(scope="module")
def scene():
    c = p.connect(p.DIRECT)
    col = p.createCollisionShape(p.GEOM_BOX, halfExtents=HALF.tolist(), physicsClientId=c)
    vis = p.createVisualShape(p.GEOM_BOX, halfExtents=HALF.tolist(), physicsClientId=c)
    body = p.createMultiBody(0, col, vis, CENTER.tolist(), physicsClientId=c)
    yield c, body
    p.disconnect(c)


CAMERAS = [
    Camera(position=[0.5, 0.0, 1.0], look_at=[0.5, 0.0, 0.0], up=[1, 0, 0], fov_deg=45, width=320, height=240),
    Camera(position=[1.0, 0.3, 0.6], look_at=[0.5, 0.0, 0.02], up=[0, 0, 1], fov_deg=50, width=256, height=200),
]


@pytest.mark.parametrize("cam", CAMERAS)
def test_backprojected_points_lie_on_the_box(scene, cam):
    c, body = scene
    rgbd = capture(c, cam)
    pts = rgbd.points[rgbd.seg == body]
    assert len(pts) > 500
    # every point is on the box surface: inside the box (+0.5 mm) and on at least one face
    d = np.abs(pts - CENTER) - HALF
    assert np.all(d <= 5e-4)
    assert np.all(np.max(d, axis=1) >= -5e-4)
    # the visible faces span the box: extents within 2 px of the truth along the seen axes
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    assert np.allclose(hi[2], CENTER[2] + HALF[2], atol=5e-4)  # the top face is at its height
    assert np.allclose(lo[:2], (CENTER - HALF)[:2], atol=4e-3)
    assert np.allclose(hi[:2], (CENTER + HALF)[:2], atol=4e-3)


def test_depth_is_distance_along_the_optical_axis(scene):
    c, body = scene
    cam = CAMERAS[0]
    rgbd = capture(c, cam)
    top = rgbd.seg == body
    # looking straight down from z = 1.0 at the top face (z = 0.06): depth 0.94 m everywhere on it
    assert np.allclose(rgbd.depth[top & (rgbd.points[..., 2] > 0.059)], 1.0 - 0.06, atol=5e-4)
    view, proj = matrices(cam)
    again = backproject(rgbd.depth, view, proj)
    assert np.allclose(again[top], rgbd.points[top])


def test_depth_noise_is_seeded(scene):
    c, _ = scene
    cam = CAMERAS[0].model_copy(update={"depth_noise_std": 0.002})
    a = capture(c, cam, np.random.default_rng(3)).depth
    b = capture(c, cam, np.random.default_rng(3)).depth
    clean = capture(c, CAMERAS[0]).depth
    ok = np.isfinite(clean)
    assert np.array_equal(a[ok], b[ok])
    assert 0.001 < np.std(a[ok] - clean[ok]) < 0.003


def test_cloud_crop_downsample_normals(scene):
    c, body = scene
    cloud = Cloud.concat([from_rgbd(capture(c, cam)) for cam in CAMERAS])
    box = crop(cloud, CENTER - HALF - 0.001, CENTER + HALF + 0.001)
    assert body in set(box.labels.tolist())
    obj = voxel_downsample(box.select(box.labels == body), 0.004)
    assert len(obj) < len(box)
    obj = estimate_normals(obj)
    top = obj.points[:, 2] > CENTER[2] + HALF[2] - 1e-3
    inner = top & np.all(np.abs(obj.points[:, :2] - CENTER[:2]) < HALF[:2] - 0.01, axis=1)
    assert inner.sum() > 20
    assert np.all(obj.normals[inner] @ [0, 0, 1] > 0.99)  # outward (towards the camera), flat
    assert np.median(obj.curvature[inner]) < 0.01


def test_camera_looking_away_is_warned():
    good = GraspParams()
    assert camera_warnings(good) == []
    away = GraspParams(camera=Camera(position=[0.5, 0.0, 0.9], look_at=[0.5, 0.0, 2.0]))
    assert any("camera" in w and "table" in w for w in camera_warnings(away))
    sideways = GraspParams(camera=Camera(position=[0.5, 0.0, 0.9], look_at=[-2.0, 3.0, 0.0]))
    assert any("looks away" in w for w in camera_warnings(sideways))
    assert sees_box(good.camera, good.workspace.min, good.workspace.max)


@pytest.mark.parametrize("suffix", [".npz", ".ply"])
def test_save_cloud(tmp_path, suffix):
    from robocfg.grasp.cloud import save_cloud

    cloud = Cloud(np.array([[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]), np.array([3, 4]), np.zeros((2, 3)),
                  np.array([[0, 0, 1.0], [1.0, 0, 0]]))
    path = save_cloud(cloud, tmp_path / f"c{suffix}")
    if suffix == ".npz":
        data = np.load(path)
        assert np.allclose(data["points"], cloud.points) and np.array_equal(data["labels"], [3, 4])
    else:
        lines = path.read_text().splitlines()
        assert lines[0] == "ply" and "element vertex 2" in lines
        assert lines[-1].split() == ["0.400000", "0.500000", "0.600000", "1.000000", "0.000000", "0.000000", "4"]
        import trimesh  # another PLY reader reads the file back

        assert np.allclose(trimesh.load(path, process=False).vertices, cloud.points)
    with pytest.raises(ValueError):
        save_cloud(cloud, tmp_path / "c.txt")
