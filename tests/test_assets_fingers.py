"""robocfg.assets.fingers: pad geometry by URDF FK; set_width on linkage grippers hits the width asked."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from _sim_helpers import make_task

from robocfg.assets.fingers import (
    closing_axis,
    finger_points,
    pad_gap,
    pad_midpoint,
    pad_points,
    width_curve,
)
from robocfg.assets.paths import Resolver
from robocfg.checks import load_robot
from robocfg.config.types import AXIS_INDEX

ROOT = Path(__file__).resolve().parent.parent
UR5E = ROOT / "robocfg" / "data" / "robots" / "ur5e_robotiq_2f85.yaml"


def _curve(path: Path):
    r = load_robot(path)
    a = r.config.arm()
    g = a.gripper
    return width_curve(r.urdf, Resolver(r.path.parent), a.ee_link, AXIS_INDEX[a.ee_axis], list(g.finger_links),
                       r.gripper_joints(a), g.open, g.closed, closing_axis(a.R_ee_graspnet))


def test_robotiq_pad_gap_and_midpoint_match_the_field_notes():
    """2F-85: 86 mm open, ≈ 50 mm at finger_joint 0.368, 1.5 mm at 0.8; pads 130 mm from tool0 open, 144 closed."""
    r = load_robot(UR5E)
    a = r.config.arm()
    links = list(a.gripper.finger_links)
    pts = finger_points(r.urdf, Resolver(r.path.parent), links)
    x = closing_axis(a.R_ee_graspnet)
    assert np.allclose(x, [1, 0, 0])
    out = {}
    for q in (0.0, 0.368, 0.8):
        pads = pad_points(r.urdf, a.ee_link, links, pts, {"finger_joint": q}, 2)
        out[q] = (pad_gap(pads, x), pad_midpoint(pads))
    assert out[0.0][0] == pytest.approx(0.086, abs=5e-4)
    assert out[0.368][0] == pytest.approx(0.050, abs=2e-3)
    assert out[0.8][0] == pytest.approx(0.0015, abs=5e-4)
    assert out[0.0][1][2] == pytest.approx(0.130, abs=1e-3) and out[0.8][1][2] == pytest.approx(0.144, abs=1e-3)
    assert abs(out[0.0][1][0]) < 1e-6 and abs(out[0.0][1][1]) < 1e-3  # on the axis


def test_width_curve_is_monotonic_and_not_linear_for_a_linkage():
    s, gaps = _curve(UR5E)
    assert np.all(np.diff(gaps) > 0)  # closed (s = 0) → open (s = 1)
    linear = gaps[0] + s * (gaps[-1] - gaps[0])
    assert np.max(np.abs(gaps - linear)) > 0.002  # ≈ 3 mm: the reason set_width needs it


def test_set_width_reaches_the_width_on_a_linkage_gripper(tmp_path):
    """A linear joint map would miss 30 mm by ≈ 3.5 mm on the 2F-85; the FK curve hits it."""
    from robocfg.sim.world import World

    with World(make_task(tmp_path, UR5E)) as w:
        g = w.robot.arm().gripper
        for width in (0.07, 0.03):
            g.set_width(width)
            w.step(round(0.6 / w.dt))
            assert g.width() == pytest.approx(width, abs=1.5e-3)


ROBOTS = sorted((ROOT / "robocfg" / "data" / "robots").glob("*.yaml"))


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_width_curve_is_the_sweep_of_pad_points_bit_for_bit(path: Path):
    """width_curve inverts ee_link's pose once for a sweep that does not move it: the same gaps, to
    the bit, as pad_points recomputing it at every opening."""
    from robocfg.config.robot import ParallelGripperConfig

    r = load_robot(path)
    arms = [a for a in r.config.arms if isinstance(a.gripper, ParallelGripperConfig)]
    if not arms:
        pytest.skip("no parallel gripper")
    for a in arms:
        g = a.gripper
        links, leaders = list(g.finger_links), r.gripper_joints(a)
        resolver = Resolver(r.path.parent, r.config.package_dirs)
        s, gaps = width_curve(r.urdf, resolver, a.ee_link, AXIS_INDEX[a.ee_axis], links, leaders, g.open, g.closed,
                              closing_axis(a.R_ee_graspnet))
        pts = finger_points(r.urdf, resolver, links)
        qo, qc = np.asarray(g.open, float), np.asarray(g.closed, float)
        want = [pad_gap(pad_points(r.urdf, a.ee_link, links, pts, dict(zip(leaders, qc + k * (qo - qc), strict=True)),
                                   AXIS_INDEX[a.ee_axis]), closing_axis(a.R_ee_graspnet)) for k in s]
        assert gaps.tolist() == want


def test_width_curve_of_a_hand_moved_by_the_swept_joint_recomputes_its_pose():
    """A leader on ee_link's own chain moves the hand with the fingers: the pose is not taken as fixed."""
    from robocfg.assets.urdf import Link, Urdf

    r = load_robot(UR5E)
    a = r.config.arm()
    g = a.gripper
    links, leaders = list(g.finger_links), r.gripper_joints(a)
    ee_joint = r.urdf.joint_to_child(a.ee_link)
    assert ee_joint is not None
    resolver = Resolver(r.path.parent, r.config.package_dirs)
    # the hand hung below the leader: an extra link whose parent joint is the leader's twin
    u = r.urdf
    twin = replace(ee_joint, name="hand_twin", type="revolute", lower=-1.0, upper=1.0, axis=np.array([0.0, 0.0, 1.0]),
                   parent=a.ee_link, child="hand_tip", mimic=None)
    moved = Urdf(u.path, u.name, {**u.links, "hand_tip": Link("hand_tip", None, (), ())}, {**u.joints, "hand_twin": twin},
                 u.root, u.dof_joints)
    s, gaps = width_curve(moved, resolver, "hand_tip", AXIS_INDEX[a.ee_axis], links, [*leaders, "hand_twin"],
                          [*g.open, 0.5], [*g.closed, -0.5], closing_axis(a.R_ee_graspnet))
    pts = finger_points(moved, resolver, links)
    qo, qc = np.asarray([*g.open, 0.5]), np.asarray([*g.closed, -0.5])
    names = [*leaders, "hand_twin"]
    want = [pad_gap(pad_points(moved, "hand_tip", links, pts, dict(zip(names, qc + k * (qo - qc), strict=True)),
                               AXIS_INDEX[a.ee_axis]), closing_axis(a.R_ee_graspnet)) for k in s]
    assert gaps.tolist() == want
    fixed = [pad_gap(pad_points(moved, "hand_tip", links, pts, dict(zip(names, qc + k * (qo - qc), strict=True)),
                                AXIS_INDEX[a.ee_axis], ee_inv=np.linalg.inv(moved.link_pose("hand_tip", dict(zip(names, qc, strict=True))))),
                     closing_axis(a.R_ee_graspnet)) for k in s]
    assert fixed != want  # the hand's pose taken as fixed would give other gaps
