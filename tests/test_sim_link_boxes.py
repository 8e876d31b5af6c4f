"""robocfg.sim.link_boxes: a gripper's layout (links, shapes) read once gives the measurements of
one read at every opening, to the bit (measure_gripper reads it once for its nine openings)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from _sim_helpers import make_task

from robocfg.config.robot import ParallelGripperConfig
from robocfg.grasp.gripper_model import CLOSING_SAMPLES, grasp_from_ee
from robocfg.sim.link_boxes import LinkBoxes, gripper_layout, measure_link_boxes
from robocfg.sim.world import World

ROBOTS = Path(__file__).resolve().parents[1] / "robocfg" / "data" / "robots"


def _same(a: LinkBoxes, b: LinkBoxes) -> bool:
    return (a.names == b.names and np.array_equal(a.lo, b.lo) and np.array_equal(a.hi, b.hi)
            and np.array_equal(a.finger, b.finger) and len(a.obbs) == len(b.obbs)
            and all(x.touches == y.touches and all(np.array_equal(u, v) for u, v in zip(x[:4], y[:4], strict=True))
                    for x, y in zip(a.obbs, b.obbs, strict=True)))


@pytest.mark.parametrize("robot", ["panda", "ur5e_robotiq_2f85", "xarm6", "ur10e_robotiq_2f140"])
def test_a_layout_read_once_measures_as_one_read_at_each_opening(tmp_path, robot):
    task = make_task(tmp_path, ROBOTS / f"{robot}.yaml")
    with World(task, visuals=False) as world:
        arm = world.robot.arm()
        assert isinstance(arm.config.gripper, ParallelGripperConfig)
        G_T_ee = grasp_from_ee(arm.config)
        layout = gripper_layout(world.robot, arm)
        assert any(len(local) for shapes in layout.shapes for local, _ in shapes)
        for f in np.linspace(1.0, 0.0, CLOSING_SAMPLES):
            arm.gripper.reset(float(f))
            assert _same(measure_link_boxes(world.robot, arm, G_T_ee, layout), measure_link_boxes(world.robot, arm, G_T_ee))
        arm.gripper.reset(0.0)
        closed = measure_link_boxes(world.robot, arm, G_T_ee, layout)
        arm.gripper.reset(1.0)
        assert not _same(closed, measure_link_boxes(world.robot, arm, G_T_ee, layout))  # the boxes do move
