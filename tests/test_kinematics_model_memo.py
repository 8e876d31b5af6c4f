"""KinematicModel.from_robot: the URDF text handed to pinocchio and the last builds kept and copied.

A file without continuous joints goes to pinocchio as read (no parse and re-serialisation): the
model must be the one the re-serialised tree gives. A repeated build is a copy of a kept one: the
same model, sharing nothing mutable, and an IK query on one leaves the other's answers unchanged.
"""

from __future__ import annotations

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
