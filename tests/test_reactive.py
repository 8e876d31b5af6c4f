"""Reactive controller (placo QP) on the Panda, kinematically (no physics): limits, convergence,
collision margin, Jacobian rows, failure fallback, start in penetration."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from robocfg.checks import load_robot
from robocfg.motion.reactive import EnvShape, ReactiveController, ReactiveSettings
from robocfg.motion.reactive.limits import step_bounds
from robocfg.motion.reactive.setup import arm_spec

ROOT = Path(__file__).resolve().parent.parent
DT = 1.0 / 240.0


@pytest.fixture(scope="module")
def panda():
    return load_robot(ROOT / "robocfg" / "data" / "robots" / "panda.yaml")


def _spec(panda):
    return arm_spec(panda, panda.urdf_path, np.eye(4), acceleration=10.0)


def _controller(panda, env=(), **kw):
    shapes = [EnvShape("ground", "halfspace", (), np.eye(4), obstacle=False), *env]
    return ReactiveController(_spec(panda), shapes, ReactiveSettings(dt=DT, **kw))


def _target(pos, R=None):
    T = np.eye(4)
    T[:3, :3] = np.diag([1.0, -1.0, -1.0]) if R is None else R
    T[:3, 3] = pos
    return T


def _sphere(pos, r):
    T = np.eye(4)
    T[:3, 3] = pos
    return EnvShape("ball", "sphere", (r,), T)


# ---- joint box ------------------------------------------------------------------------------
def test_step_bounds_respect_velocity_acceleration_and_braking():
    q = np.array([0.0, 0.95, -0.5])
    dq_prev = np.array([0.0, 1.0, -2.0])
    lower, upper = np.full(3, -1.0), np.full(3, 1.0)
    vmax, amax = np.full(3, 2.0), np.full(3, 10.0)
    lo, hi = step_bounds(q, dq_prev, lower, upper, vmax, amax, DT)
    assert np.all(lo <= hi + 1e-15)
    assert np.all(np.abs(lo) <= vmax * DT + 1e-12) and np.all(np.abs(hi) <= vmax * DT + 1e-12)
    # acceleration band around the previous velocity
    assert np.all(hi / DT <= dq_prev + amax * DT + 1e-9) or np.any(q + hi >= upper - 1e-12)
    # joint 1 is 5 cm from its upper limit: the allowed speed lets it brake in time
    assert hi[1] / DT <= np.sqrt(2 * amax[1] * (upper[1] - q[1])) + 1e-9
    assert q[1] + hi[1] <= upper[1]


def test_step_bounds_never_empty_when_braking_is_impossible():
    # moving at full speed right at the limit: the acceleration band lies beyond the allowed band
    lo, hi = step_bounds(np.array([0.999]), np.array([2.0]), np.array([-1.0]), np.array([1.0]),
                         np.array([2.0]), np.array([10.0]), DT)
    assert lo[0] <= hi[0]
    assert 0.999 + hi[0] <= 1.0 + 1e-12


# ---- convergence and limits -----------------------------------------------------------------
def test_static_target_converges_within_1mm_and_001rad_and_respects_limits(panda):
    c = _controller(panda)
    spec = c.arm
    c.reset(spec.posture)
    goal = _target([0.5, 0.2, 0.35])
    qs = []
    for _ in range(360):
        r = c.step(goal)
        assert r.status == "ok"
        qs.append(r.q)
    T = c.tcp_pose(qs[-1])  # FK of the final command
    assert np.linalg.norm(T[:3, 3] - goal[:3, 3]) < 1e-3
    R_err = T[:3, :3].T @ goal[:3, :3]
    assert np.arccos(np.clip((np.trace(R_err) - 1) / 2, -1, 1)) < 0.01
    q = np.array(qs)
    assert np.all(q >= spec.lower - 1e-9) and np.all(q <= spec.upper + 1e-9)
    v = np.diff(np.vstack([spec.posture, q]), axis=0) / DT
    assert np.all(np.abs(v) <= spec.velocity_limits + 1e-6)
    a = np.diff(v, axis=0) / DT
    assert np.max(np.abs(a) - spec.acceleration_limits) <= 1e-6


def test_unreachable_target_is_held_without_thrashing(panda):
    c = _controller(panda)
    c.reset(c.arm.posture)
    goal = _target([1.5, 0.0, 0.4])
    qs = [c.step(goal).q for _ in range(600)]
    tail = np.array(qs[-60:])
    assert np.ptp(tail, axis=0).max() < 0.01  # settled after 2.5 s, not swaying
    assert np.linalg.norm(c.tcp_pose(qs[-1])[:3, 3] - goal[:3, 3]) > 0.5  # and honestly not there


# ---- collisions -----------------------------------------------------------------------------
def test_obstacle_on_the_path_keeps_the_margin(panda):
    margin = 0.02
    start = np.array([0.307, 0.0, 0.487])
    goal = np.array([0.5, 0.3, 0.3])
    c = _controller(panda, [_sphere(start + 0.5 * (goal - start), 0.04)], margin=margin)
    c.reset(c.arm.posture)
    worst = np.inf
    for _ in range(600):
        r = c.step(_target(goal))
        worst = min(worst, r.clearance)
    assert worst >= margin - 0.003
    assert np.linalg.norm(c.tcp_pose()[:3, 3] - goal) < 0.005


def test_model_distance_matches_pybullet_closest_points(panda):
    import pybullet as p

    ball = _sphere([0.45, 0.1, 0.35], 0.05)
    c = _controller(panda, [ball])
    cid = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(str(panda.urdf_path), useFixedBase=True, physicsClientId=cid)
        sph = p.createMultiBody(0, p.createCollisionShape(p.GEOM_SPHERE, radius=0.05, physicsClientId=cid),
                                basePosition=[0.45, 0.1, 0.35], physicsClientId=cid)
        index = {p.getJointInfo(body, i, physicsClientId=cid)[1].decode(): i for i in range(p.getNumJoints(body, physicsClientId=cid))}
        rng = np.random.default_rng(1)
        for _ in range(3):
            q = c.arm.posture + rng.uniform(-0.4, 0.4, 7)
            for name, v in zip(c.arm.joint_names, q, strict=True):
                p.resetJointState(body, index[name], v, physicsClientId=cid)
            for name, v in c.arm.other_joints.items():
                p.resetJointState(body, index[name], v, physicsClientId=cid)
            c.reset(q)
            ours = min(d for a, b, d in c.distances() if b == "env:ball")
            theirs = min(pt[8] for pt in p.getClosestPoints(body, sph, 1.0, physicsClientId=cid))
            assert abs(ours - theirs) < 0.004  # both use convex hulls of the same meshes
    finally:
        p.disconnect(cid)


def test_collision_rows_match_finite_differences(panda):
    c = _controller(panda)
    c.reset(c.arm.posture + 0.1)
    r = c.robot
    p_local = np.array([0.02, -0.01, 0.05])
    T = np.asarray(r.get_T_world_frame("panda_hand"))
    p_world = T[:3, :3] @ p_local + T[:3, 3]
    n = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    q_full = np.asarray(r.state.q)
    c.rows.forget_jacobians()
    row = c.rows.normal_row(r.model.getJointId("panda_joint7"), p_world, n, q_full)
    h = 1e-6
    for k in range(7):
        dq = np.zeros(7)
        dq[k] = h
        c._set_q(c.arm.posture + 0.1 + dq)
        T2 = np.asarray(r.get_T_world_frame("panda_hand"))
        moved = T2[:3, :3] @ p_local + T2[:3, 3]
        assert abs(n @ (moved - p_world) / h - row[k]) < 1e-4


def test_solver_failure_falls_back_to_zero_velocity(panda):
    c = _controller(panda)
    c.reset(c.arm.posture)
    c.step(_target([0.5, 0.1, 0.4]))

    class Broken:
        def solve(self, apply):
            raise RuntimeError("infeasible")

    c.solver = Broken()
    q_before = c.q.copy()
    r = c.step(_target([0.5, 0.1, 0.4]))
    assert r.status == "fallback"
    assert np.allclose(r.dq, 0.0) and np.allclose(r.q, q_before)
    assert c.fallbacks == 1


def test_start_in_penetration_recovers_instead_of_freezing(panda):
    c = _controller(panda)
    tcp = c.tcp_pose(c.arm.posture)[:3, 3]
    ball = _sphere(tcp + np.array([0.0, 0.0, 0.1]), 0.04)  # inside the hand at the start
    c = _controller(panda, [ball])
    c.reset(c.arm.posture)
    first = c.step(_target(tcp)).clearance
    assert first < 0
    for _ in range(240):
        r = c.step(_target(tcp))
    assert r.clearance > first + 0.02  # pushed itself out
    assert r.status in ("ok", "soft")
