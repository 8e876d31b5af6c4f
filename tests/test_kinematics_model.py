"""KinematicModel: FK against PyBullet for every shipped robot, Jacobians against finite differences."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import NotFound, RobocfgError
from robocfg.kinematics.model import KinematicModel

ROBOTS = sorted((Path(__file__).parents[1] / "robocfg" / "data" / "robots").glob("*.yaml"))
PANDA = Path(__file__).parents[1] / "robocfg" / "data" / "robots" / "panda.yaml"
# the UR5e test robot (airo-models URDF): ±2π joints, which the IK wraps
UR5E = Path(__file__).parent / "data" / "ur5e_ik.yaml"
FK_ROBOTS = [*ROBOTS, UR5E]
N_CONFIGS = 5


def _random_pose(rng: np.random.Generator) -> np.ndarray:
    import pinocchio as pin

    T = np.eye(4)
    T[:3, :3] = pin.exp3(rng.normal(size=3))
    T[:3, 3] = rng.uniform(-1.0, 1.0, 3)
    return T


def _pybullet_link_poses(robot, model: KinematicModel, configs: list[np.ndarray], base: np.ndarray):
    """For each configuration: world_T_link of every non-root link, from PyBullet (link frames,
    getLinkState [4], [5] with computeForwardKinematics)."""
    import pinocchio as pin
    import pybullet as p

    cid = p.connect(p.DIRECT)
    try:
        quat = pin.Quaternion(base[:3, :3]).coeffs().tolist()  # x y z w
        body = p.loadURDF(str(robot.urdf_path), base[:3, 3].tolist(), quat, useFixedBase=True, physicsClientId=cid)
        joints = {p.getJointInfo(body, i, physicsClientId=cid)[1].decode(): i
                  for i in range(p.getNumJoints(body, physicsClientId=cid))}
        links = {p.getJointInfo(body, i, physicsClientId=cid)[12].decode(): i for i in joints.values()}
        out = []
        for q in configs:
            values = dict(model.locked)
            values.update(zip(model.joint_names, q.tolist(), strict=True))
            for name, v in values.items():
                p.resetJointState(body, joints[name], v, physicsClientId=cid)
            poses = {}
            for link, i in links.items():
                st = p.getLinkState(body, i, computeForwardKinematics=True, physicsClientId=cid)
                T = np.eye(4)
                T[:3, :3] = np.array(p.getMatrixFromQuaternion(st[5])).reshape(3, 3)
                T[:3, 3] = st[4]
                poses[link] = T
            out.append(poses)
        return out
    finally:
        p.disconnect(cid)


def _assert_pose_close(A: np.ndarray, B: np.ndarray, what: str, tol: float = 1e-6) -> None:
    import pinocchio as pin

    dp = np.linalg.norm(A[:3, 3] - B[:3, 3])
    dr = np.linalg.norm(pin.log3(A[:3, :3].T @ B[:3, :3]))
    assert dp <= tol and dr <= tol, f"{what}: position off by {dp:.2e} m, rotation by {dr:.2e} rad"


@pytest.mark.parametrize("path", FK_ROBOTS, ids=[p.stem for p in FK_ROBOTS])
@pytest.mark.parametrize("mounted", [False, True], ids=["identity", "mounted"])
def test_fk_matches_pybullet(path: Path, mounted: bool) -> None:
    rng = np.random.default_rng(3)
    robot = load_robot(path)
    base = _random_pose(rng) if mounted else np.eye(4)
    model = KinematicModel.from_robot(robot, base_pose=base if mounted else None)
    configs = [rng.uniform(model.lower, model.upper) for _ in range(N_CONFIGS)]
    for q, poses in zip(configs, _pybullet_link_poses(robot, model, configs, base), strict=True):
        assert len(poses) >= model.nq
        for link, T_pb in poses.items():
            _assert_pose_close(model.fk(q, link), T_pb, f"{path.stem} {link}", tol=1e-6)


@pytest.mark.parametrize("path", ROBOTS, ids=[p.stem for p in ROBOTS])
def test_tcp_is_offset_along_ee_axis(path: Path) -> None:
    robot = load_robot(path)
    arm = robot.config.arm()
    model = KinematicModel.from_robot(robot)
    q = np.random.default_rng(0).uniform(model.lower, model.upper)
    T_ee, T_tcp = model.fk(q, "ee"), model.fk(q, "tcp")
    axis = T_ee[:3, AXIS_INDEX[arm.ee_axis]]
    np.testing.assert_allclose(T_tcp[:3, 3], T_ee[:3, 3] + arm.tcp_offset * axis, atol=1e-12)
    np.testing.assert_allclose(T_tcp[:3, :3], T_ee[:3, :3], atol=1e-12)
    np.testing.assert_allclose(model.fk(q, arm.ee_link), T_ee, atol=1e-12)


@pytest.mark.parametrize("frame", ["tcp", "ee"])
def test_jacobian_matches_finite_differences(frame: str) -> None:
    import pinocchio as pin

    robot = load_robot(PANDA)
    rng = np.random.default_rng(1)
    model = KinematicModel.from_robot(robot, base_pose=_random_pose(rng))
    h = 1e-6
    for _ in range(5):
        q = rng.uniform(model.lower + 0.01, model.upper - 0.01)
        J = model.jacobian(q, frame)
        assert J.shape == (6, model.nq)
        T0 = model.fk(q, frame)
        for k in range(model.nq):
            dq = np.zeros(model.nq)
            dq[k] = h
            Tp, Tm = model.fk(q + dq, frame), model.fk(q - dq, frame)
            v = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
            w = (pin.log3(Tp[:3, :3] @ T0[:3, :3].T) - pin.log3(Tm[:3, :3] @ T0[:3, :3].T)) / (2 * h)
            np.testing.assert_allclose(J[:3, k], v, atol=1e-6)
            np.testing.assert_allclose(J[3:, k], w, atol=1e-6)


def test_interface_and_locked_gripper() -> None:
    robot = load_robot(PANDA)
    model = KinematicModel.from_robot(robot)
    arm = robot.config.arm()
    assert model.joint_names == robot.arm_joints(arm)
    assert model.nq == len(model.joint_names) == len(model.lower) == len(model.upper) == len(model.velocity_limits)
    assert np.all(model.lower < model.upper)
    leaders = robot.gripper_joints(arm)
    for name, value in zip(leaders, arm.gripper.open, strict=True):
        assert model.locked[name] == pytest.approx(value)
    for follower in robot.mimic_followers(leaders):
        m = robot.urdf.joints[follower].mimic
        assert model.locked[follower] == pytest.approx(m.multiplier * model.locked[m.joint] + m.offset)


def test_gripper_q_changes_finger_pose_not_tcp() -> None:
    robot = load_robot(PANDA)
    arm = robot.config.arm()
    leader = robot.gripper_joints(arm)[0]
    opened = KinematicModel.from_robot(robot)
    closed = KinematicModel.from_robot(robot, gripper_q={leader: arm.gripper.closed[0]})
    q = opened.home
    finger = arm.gripper.finger_links[0]
    assert np.linalg.norm(opened.fk(q, finger)[:3, 3] - closed.fk(q, finger)[:3, 3]) > 1e-3
    np.testing.assert_allclose(opened.fk(q), closed.fk(q), atol=1e-12)


def test_bad_inputs() -> None:
    model = KinematicModel.from_robot(load_robot(PANDA))
    with pytest.raises(NotFound, match="known"):
        model.fk(model.home, "no_such_link")
    with pytest.raises(RobocfgError):
        model.fk(np.zeros(model.nq + 1))
    with pytest.raises(RobocfgError):
        KinematicModel.from_robot(load_robot(PANDA), base_pose=np.full((4, 4), np.nan))


def test_fk_positions_are_the_translations_of_fk() -> None:
    """One call for a sampled path gives, bit for bit, the positions of ``fk`` row by row; frame
    names are looked up once and stay right (a cached id must not leak between names)."""
    robot = load_robot(PANDA)
    model = KinematicModel.from_robot(robot)
    finger = robot.config.arm().gripper.finger_links[0]
    rng = np.random.default_rng(3)
    qs = rng.uniform(model.lower, model.upper, (9, model.nq))
    for frame in ("ee", "tcp", "ee", finger):
        want = np.array([model.fk(q, frame)[:3, 3] for q in qs])
        assert model.fk_positions(qs, frame).tobytes() == want.tobytes(), frame
    assert np.linalg.norm(model.fk_positions(qs[:1], "ee") - model.fk_positions(qs[:1], finger)) > 1e-3
    with pytest.raises(RobocfgError, match="shape"):
        model.fk_positions(qs[:, :3], "ee")


def test_fk_pose_rows_are_fk_as_lists() -> None:
    """The straight lines' FK check: each row's ``fk`` as nested Python floats, the same bits."""
    model = KinematicModel.from_robot(load_robot(PANDA))
    qs = np.random.default_rng(4).uniform(model.lower, model.upper, (7, model.nq))
    for frame in ("ee", "tcp"):
        assert model.fk_pose_rows(qs, frame) == [model.fk(q, frame).tolist() for q in qs]
    with pytest.raises(RobocfgError, match="shape"):
        model.fk_pose_rows(qs[:, :3], "ee")
