"""The Gripper base is complete: every registered gripper implements the whole interface, so
callers never probe with hasattr; a suction cup answers the finger questions as documented."""

from __future__ import annotations

import inspect
from pathlib import Path

import pytest
from _sim_helpers import DATA, make_task

from robocfg.sim.gripper import base
from robocfg.sim.gripper.registry import GRIPPERS

REQUIRED = [name for name, fn in inspect.getmembers(base.Gripper, inspect.isfunction)
            if "raise NotImplementedError" in inspect.getsource(fn)]


def test_base_declares_the_interface() -> None:
    assert {"open", "close", "reset", "fraction", "state", "is_grasping"} <= set(REQUIRED)
    for name in ("set_force", "width", "update"):
        assert callable(getattr(base.Gripper, name))


@pytest.mark.parametrize("type_name", sorted(GRIPPERS))
def test_every_gripper_implements_the_interface(type_name: str) -> None:
    cls = GRIPPERS[type_name]
    missing = [m for m in REQUIRED if getattr(cls, m) is getattr(base.Gripper, m)]
    assert not missing, f"{cls.__name__} lacks {missing}"


def test_suction_answers_fraction_width_and_force(tmp_path: Path) -> None:
    from robocfg.sim.world import World

    with World(make_task(tmp_path, DATA / "sim_suction_robot.yaml")) as world:
        g = world.robot.arm().gripper
        assert g is not None and g.grasps_at_surface
        assert g.width() is None  # no fingers
        g.set_force(50.0)  # no force setting: accepted, changes nothing
        assert g.fraction() == 1.0 and g.state() == 1.0
        g.close()
        assert g.fraction() == 0.0 and g.state() == -1.0
        g.reset(1.0)
        assert g.fraction() == 1.0
