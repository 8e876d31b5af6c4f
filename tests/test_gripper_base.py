"""The Gripper base is complete: every registered gripper implements the whole interface (the
registry refuses one that does not), so callers never probe with hasattr; a suction cup answers
the finger questions as documented."""

from __future__ import annotations

from pathlib import Path

import pytest
from _sim_helpers import DATA, make_task

from robocfg.errors import RobocfgError
from robocfg.sim.gripper import base
from robocfg.sim.gripper.registry import GRIPPERS, register


def test_base_declares_the_interface() -> None:
    assert set(base.Gripper.__abstractmethods__) == {"open", "close", "reset", "fraction", "state", "is_grasping"}
    for name in ("set_force", "width", "update"):
        assert callable(getattr(base.Gripper, name))


@pytest.mark.parametrize("type_name", sorted(GRIPPERS))
def test_every_gripper_implements_the_interface(type_name: str) -> None:
    assert not GRIPPERS[type_name].__abstractmethods__


def test_registry_refuses_an_incomplete_gripper() -> None:
    class HalfGripper(base.Gripper):
        def open(self) -> None: ...

        def close(self) -> None: ...

    with pytest.raises(RobocfgError, match="does not implement fraction, is_grasping, reset, state"):
        register("half-test")(HalfGripper)
    assert "half-test" not in GRIPPERS


def test_suction_answers_fraction_width_and_force(tmp_path: Path) -> None:
    from robocfg.sim.world import World

    cube = {"name": "cube", "shape": "box", "size": [0.04, 0.04, 0.04], "position": [0.6, 0.3, 0.02]}
    with World(make_task(tmp_path, DATA / "sim_suction_robot.yaml", objects=[cube])) as world:
        g = world.robot.arm().gripper
        assert g is not None and g.grasps_at_surface
        assert g.width() is None  # no fingers
        g.set_force(50.0)  # no force setting: accepted, changes nothing
        assert g.fraction() == 1.0 and g.state() == 1.0
        g.close()
        assert g.fraction() == 0.0 and g.state() == -1.0
        g.reset(1.0)
        assert g.fraction() == 1.0
