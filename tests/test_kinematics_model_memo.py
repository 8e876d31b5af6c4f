"""KinematicModel.from_robot: the URDF text handed to pinocchio and the last builds kept and copied.

A file without continuous joints goes to pinocchio as read (no parse and re-serialisation): the
model must be the one the re-serialised tree gives. A repeated build is a copy of a kept one: the
same model, sharing nothing mutable, and an IK query on one leaves the other's answers unchanged.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import robocfg.kinematics.model as km_module
from robocfg.assets.urdf_xml import read_urdf_xml, revolute_continuous
from robocfg.checks import load_robot
from robocfg.kinematics.model import KinematicModel, _urdf_xml_without_continuous

ROBOTS = sorted((Path(__file__).parents[1] / "robocfg" / "data" / "robots").glob("*.yaml"))
PANDA = Path(__file__).parents[1] / "robocfg" / "data" / "robots" / "panda.yaml"


@pytest.mark.parametrize("path", ROBOTS, ids=lambda p: p.stem)
def test_the_text_handed_to_pinocchio_builds_the_model_of_the_round_trip(path: Path) -> None:
    robot = load_robot(path)
    km_module._XML_MEMO.clear()
    xml, converted = _urdf_xml_without_continuous(str(robot.urdf_path))
    root = read_urdf_xml(robot.urdf_path)
    assert converted == frozenset(revolute_continuous(root, np.pi))
    assert pin.buildModelFromXML(xml) == pin.buildModelFromXML(ET.tostring(root, encoding="unicode"))


def test_a_file_with_continuous_joints_is_converted(tmp_path: Path) -> None:
    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"/><link name="b"/>'
                    '<joint name="yaw" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>'
                    "</robot>")
    xml, converted = _urdf_xml_without_continuous(str(urdf))
    assert converted == {"yaw"}
    model = pin.buildModelFromXML(xml)
    assert model.nq == 1 and list(model.upperPositionLimit) == [np.pi]


def _panda_task_base() -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = [0.1, -0.2, 0.05]
    T[:3, :3] = pin.rpy.rpyToMatrix(0.0, 0.0, 0.3)
    return T


def test_a_repeated_build_is_an_equal_model_sharing_nothing_mutable(monkeypatch) -> None:
    robot = load_robot(PANDA)
    km_module._BUILT.clear()
    builds = []
    build = KinematicModel._build.__func__  # type: ignore[attr-defined]
    monkeypatch.setattr(KinematicModel, "_build", classmethod(lambda cls, *a: builds.append(a) or build(cls, *a)))
    base = _panda_task_base()
    a = KinematicModel.from_robot(robot, base_pose=base)
    b = KinematicModel.from_robot(robot, base_pose=base.copy())
    assert len(builds) == 1
    assert a.model == b.model and a.model is not b.model and a.data is not b.data
    for name in ("lower", "upper", "velocity_limits", "wrap", "home", "base_pose", "continuous"):
        x, y = getattr(a, name), getattr(b, name)
        assert np.array_equal(x, y) and x is not y, name
    assert a.locked == b.locked and a.locked is not b.locked and a.robot is robot
    # another base pose, arm, override, config or parsed URDF builds anew
    shifted = base.copy()
    shifted[0, 3] += 1e-12
    KinematicModel.from_robot(robot, base_pose=shifted)
    KinematicModel.from_robot(robot, base_pose=base, gripper_q={"panda_finger_joint1": 0.01})
    KinematicModel.from_robot(replace(robot, config=robot.config.model_copy()), base_pose=base)
    reparsed = load_robot(PANDA)
    reparsed.urdf = replace(robot.urdf)
    KinematicModel.from_robot(reparsed, base_pose=base)
    assert len(builds) == 5
    assert not np.array_equal(KinematicModel.from_robot(robot, base_pose=shifted).base_pose, a.base_pose)


def test_ik_on_one_copy_leaves_the_answers_of_the_next_unchanged() -> None:
    robot = load_robot(PANDA)
    km_module._BUILT.clear()
    base = _panda_task_base()
    fresh = KinematicModel._build(robot, None, base, None)
    used = KinematicModel.from_robot(robot, base_pose=base)
    rng = np.random.default_rng(3)
    targets = [used.fk(rng.uniform(used.lower, used.upper)) for _ in range(5)]
    for T in targets:  # the first copy's data, solver and caches get used
        used.ik(T, time_budget=0.2)
    again = KinematicModel.from_robot(robot, base_pose=base)
    for model in (fresh, again):
        model.solver().max_total_iter = 400
    for T in targets:
        x = fresh.ik(T, time_budget=0.2)
        y = again.ik(T, time_budget=0.2)
        assert np.array_equal(x.q, y.q) and x.pos_err == y.pos_err and x.iterations == y.iterations


_TWO_LINKS = """<?xml version="1.0"?>{doctype}
<robot name="r">{pi}
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="tip"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


_REFUSED_AS_READ = pytest.mark.parametrize("doctype,pi,xyz", [
    ("", "", "0 0\t0.333"),  # a tab inside a number
    ('\n<!DOCTYPE robot [<!ENTITY h "0.333">]>', "", "0 0 &h;"),  # a DOCTYPE with an internal entity
    ("", "\n  <?editor keep?>", "0 0 0.333"),  # a processing instruction inside the document
], ids=["tab-in-number", "doctype-entity", "processing-instruction"])


def _refused_as_read(tmp_path: Path, doctype: str, pi: str, xyz: str) -> tuple[Path, pin.Model]:
    """The two-link file and the model its ElementTree round trip gives (asserting urdfdom refuses
    the text as written, the case these tests are about)."""
    path = tmp_path / "r.urdf"
    path.write_text(_TWO_LINKS.format(doctype=doctype, pi=pi, xyz=xyz), encoding="ascii")
    with pytest.raises(ValueError):
        pin.buildModelFromXML(path.read_text())
    expected = pin.buildModelFromXML(ET.tostring(read_urdf_xml(str(path)), encoding="unicode"))
    assert expected.nq == 1 and np.isclose(expected.jointPlacements[1].translation[2], 0.333)
    return path, expected


@_REFUSED_AS_READ
def test_xml_urdfdom_reads_otherwise_goes_to_pinocchio_re_serialised(tmp_path: Path, doctype, pi, xyz) -> None:
    """A DOCTYPE, a processing instruction, a tab or line break inside an attribute: not the as-read
    shortcut, the round trip every file took before it (the same model as then)."""
    path, expected = _refused_as_read(tmp_path, doctype, pi, xyz)
    km_module._XML_MEMO.clear()
    xml, converted = _urdf_xml_without_continuous(str(path))
    assert xml == ET.tostring(read_urdf_xml(str(path)), encoding="unicode") and converted == frozenset()
    model, _ = km_module._full_model(str(path))
    assert model.nq == 1
    assert np.allclose(model.jointPlacements[1].translation, expected.jointPlacements[1].translation)


@_REFUSED_AS_READ
def test_a_text_pinocchio_refuses_as_read_is_built_from_the_round_trip(tmp_path: Path, monkeypatch, doctype, pi,
                                                                       xyz) -> None:
    """Whatever else urdfdom refuses as written (here: the screen above switched off) is built once
    more from the round trip rather than failing."""
    path, expected = _refused_as_read(tmp_path, doctype, pi, xyz)
    monkeypatch.setattr(km_module, "_PLAIN_XML_ONLY_AFTER_ROUND_TRIP", re.compile(rb"(?!)"))
    km_module._XML_MEMO.clear()
    assert _urdf_xml_without_continuous(str(path))[0] == path.read_text()  # taken as read
    model, converted = km_module._full_model(str(path))
    km_module._XML_MEMO.clear()
    assert converted == frozenset() and model.nq == 1
    assert np.allclose(model.jointPlacements[1].translation, expected.jointPlacements[1].translation)
