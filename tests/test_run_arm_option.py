"""``--arm`` is checked before anything is built or simulated, for every run kind (issue 14)."""

import pytest
from _cli import run_main

from robocfg.engine.registry import command_name, registered

KINDS = [command_name(k) for k in registered()]


@pytest.fixture
def no_world(monkeypatch):
    """Building a world fails the test: the option must be refused before."""

    def refuse(*_a, **_k):
        raise AssertionError("a world was built before --arm was checked")

    monkeypatch.setattr("robocfg.sim.world.World.__init__", refuse)


@pytest.mark.parametrize("kind", KINDS)
def test_arm_not_on_a_dual_robot_is_refused_with_a_suggestion(kind, no_world, capsys, monkeypatch):
    code, out, err = run_main(["run", kind, "--robot", "dual_panda", "--arm", "rigt", "-q"], capsys, monkeypatch)
    assert code == 2, (out, err)
    assert err.strip() == ("--arm rigt: robot 'dual_panda' has no arm 'rigt'; did you mean 'right'? "
                           "(its arms: left, right)"), err


@pytest.mark.parametrize("kind", KINDS)
def test_arm_on_a_single_arm_robot_is_refused(kind, no_world, capsys, monkeypatch):
    code, out, err = run_main(["run", kind, "--robot", "panda", "--arm", "left", "-q"], capsys, monkeypatch)
    assert code == 2, (out, err)
    assert err.strip() == "--arm left: robot 'panda' has one arm, 'arm': leave --arm out or give --arm arm", err


def test_ik_arm_is_refused_the_same_way(capsys, monkeypatch):
    code, out, err = run_main(["ik", "dual_panda", "--arm", "lft", "--position", "0.4", "0", "0.4"], capsys, monkeypatch)
    assert code == 2, (out, err)
    assert err.strip() == "--arm lft: robot 'dual_panda' has no arm 'lft'; did you mean 'left'? (its arms: left, right)"
