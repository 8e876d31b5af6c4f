"""Antipodal sampling and analytic quality on synthetic clouds with exact normals."""

import math

import numpy as np
import pytest

from robocfg.grasp.antipodal import PlannerSettings, _duplicate, plan_grasps
from robocfg.grasp.gripper_model import GripperBoxes
from robocfg.grasp.quality import antipodality, cone_angles, epsilon


def box_cloud(size, center=(0.5, 0.0, 0.0), step=0.004, yaw=0.0):
    """Points and outward normals on the 5 visible faces (not the bottom) of a box resting on z = 0."""
    sz = size[2]
    pts, nrm = [], []
    for axis, sign in [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1)]:
        u, v = [a for a in range(3) if a != axis]
        gu = np.arange(-size[u] / 2 + step / 2, size[u] / 2, step)
        gv = np.arange(-size[v] / 2 + step / 2, size[v] / 2, step)
        U, V = np.meshgrid(gu, gv)
        P = np.zeros((U.size, 3))
        P[:, u], P[:, v] = U.ravel(), V.ravel()
        P[:, axis] = sign * size[axis] / 2
        n = np.zeros(3)
        n[axis] = sign
        pts.append(P)
        nrm.append(np.tile(n, (len(P), 1)))
    P, N = np.concatenate(pts), np.concatenate(nrm)
    c, s = math.cos(yaw), math.sin(yaw)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return P @ R.T + np.array(center) + [0, 0, sz / 2], N @ R.T


def panda_like_boxes() -> GripperBoxes:
    """Hand and two fingers in the grasp frame (x approach, y closing), 8 cm open, like the Panda's."""
    lo = np.array([[-0.13, -0.10, -0.03], [-0.045, 0.040, -0.0105], [-0.045, -0.066, -0.0105]])
    hi = np.array([[-0.037, 0.10, 0.03], [0.009, 0.066, 0.0105], [0.009, -0.040, 0.0105]])
    return GripperBoxes(lo, hi, ("hand", "left", "right"), np.array([False, True, True]), 0.08)


SETTINGS = PlannerSettings(mu=0.5, num_candidates=150, top_k=5, standoff=0.1, voxel=0.004)


def plan(P, N, support=0.0, yaw_seed=0, **kw):
    return plan_grasps(P, N, P, support, panda_like_boxes(), SETTINGS, np.random.default_rng(yaw_seed), **kw)


@pytest.mark.parametrize("yaw", [0.0, 0.5])
def test_box_grasps_close_across_faces(yaw):
    P, N = box_cloud((0.05, 0.05, 0.05), yaw=yaw)
    res = plan(P, N)
    assert len(res.candidates) == SETTINGS.top_k
    face_x = np.array([math.cos(yaw), math.sin(yaw), 0.0])
    face_y = np.array([-math.sin(yaw), math.cos(yaw), 0.0])
    for c in res.candidates:
        g = c.grasp
        assert max(abs(g.closing() @ face_x), abs(g.closing() @ face_y)) > 0.97  # across a pair of faces
        assert abs(g.width - 0.05) < 0.006
        assert c.antipodality > 0.6 and c.epsilon > 0  # within 40 % of the friction cone
        assert np.allclose(g.rotation.T @ g.rotation, np.eye(3), atol=1e-9)
    best = res.candidates[0]
    assert best.grasp.approach() @ [0, 0, -1] > 0.99  # top-down ranks first
    assert 0 < best.grasp.center[2] < 0.05


def test_too_wide_object_has_no_grasp_and_counts_reasons():
    P, N = box_cloud((0.10, 0.10, 0.05))
    res = plan(P, N)
    assert res.candidates == []
    assert res.rejected["not_antipodal"] == res.seeds  # no partner within the 8 cm gap
    P, N = box_cloud((0.04, 0.10, 0.05))  # graspable across its 4 cm side only
    res = plan(P, N)
    assert res.candidates and all(abs(c.grasp.closing()[0]) > 0.97 for c in res.candidates)


@pytest.mark.parametrize("seed", [0, 1, 4, 13])
def test_support_plane_and_cloud_collisions_reject_grasps(seed):
    P, N = box_cloud((0.05, 0.05, 0.012))  # a flat tile: fingertips would hit the support
    res = plan(P, N, yaw_seed=seed)
    assert not any(c.grasp.approach() @ [0, 0, -1] > 0.99 for c in res.candidates)
    assert res.rejected["collision"] > 0
    # Without the support the best grasp squeezes the tile's sides straight from above. (Seeds 1,
    # 4 and 13 once ranked only tilted grasps first: the top face's edge row was blended into the
    # side contact normals, so the result hinged on float ties at the finger window's edges.)
    res_no_support = plan(P, N, support=None, yaw_seed=seed)
    assert res_no_support.candidates[0].grasp.approach() @ [0, 0, -1] > 0.99


def test_contact_normal_ignores_grazed_faces():
    """A pad presses only the face it faces: the tile's top-face edge row does not tilt the contact
    normal, so a level grasp across the sides is fully antipodal."""
    P, N = box_cloud((0.05, 0.05, 0.012))
    best = plan(P, N, support=None).candidates[0]
    assert best.antipodality > 0.95


def test_reach_callback_filters_and_nms_spreads():
    P, N = box_cloud((0.05, 0.05, 0.05))
    seen = []

    def reach(g):
        seen.append(g)
        return None if g.center[1] > 0 else (g, np.zeros(7))

    res = plan(P, N, reach=reach)
    assert res.rejected["unreachable"] == sum(1 for g in seen if g.center[1] > 0) > 0
    assert all(c.grasp.center[1] <= 0 and c.q is not None for c in res.candidates)
    kept = [c.grasp for c in res.candidates]
    assert len(kept) >= 2 and res.suppressed > 0  # a cube offers many near-identical grasps
    assert not any(_duplicate(a, b, SETTINGS) for i, a in enumerate(kept) for b in kept[i + 1 :])


def test_edge_contacts_are_rejected_by_curvature():
    P, N = box_cloud((0.05, 0.05, 0.05))
    curv = np.zeros(len(P))
    # mark everything within 6 mm of a vertical edge as an edge (as PCA would)
    local = P - [0.5, 0.0, 0.025]
    near_edge = (np.abs(np.abs(local[:, 0]) - 0.025) < 0.006) & (np.abs(np.abs(local[:, 1]) - 0.025) < 0.006)
    curv[near_edge] = 0.1
    res = plan(P, N, curvature=curv)
    assert res.candidates
    for c in res.candidates:
        assert max(abs(c.grasp.closing()[0]), abs(c.grasp.closing()[1])) > 0.97


def test_antipodality_and_epsilon():
    p1, p2 = np.array([-0.025, 0, 0]), np.array([0.025, 0, 0])
    n1, n2 = np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])
    assert cone_angles(p1, n1, p2, n2) == (0.0, 0.0)
    assert antipodality(p1, n1, p2, n2, 0.5) == pytest.approx(1.0)
    tilted = np.array([math.cos(0.6), 0, math.sin(0.6)])  # 34° > atan(0.5) = 26.6°
    assert antipodality(p1, n1, p2, tilted, 0.5) < 0
    e_center = epsilon(p1, n1, p2, n2, [0, 0, 0], 0.5, 0.03)
    up = np.array([0, 0, 0.02])
    e_off = epsilon(p1 + up, n1, p2 + up, n2, [0, 0, 0], 0.5, 0.03)
    assert e_center > e_off > 0  # gravity about the contact axis costs quality
    assert epsilon(p1, n1, p2, np.array([0, 0, 1.0]), [0, 0, 0], 0.5, 0.03) == 0.0  # not force closure
    assert epsilon(p1, n1, p2, n2, [0, 0, 0], 1.0, 0.03) > e_center  # more friction, more margin
