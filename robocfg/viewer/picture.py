"""The ``--png`` path of ``robocfg view``: load the YAML, pose the robot, write the sheet."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from robocfg.checks import CheckedRobot
from robocfg.sim.still_scene import StillScene
from robocfg.viewer.sheet import robot_sheet
from robocfg.viewer.source import ViewSource


def header_lines(source: ViewSource, robots: list[CheckedRobot]) -> list[str]:
    """Title and the frame numbers of each arm as the YAML gives them."""
    lines = [f"robocfg view {source.path.name}  ({source.kind}: {source.path})"]
    for robot in robots:
        for arm in robot.config.arms:
            R = np.asarray(arm.R_ee_graspnet, float)
            rows = "; ".join(" ".join(f"{v:g}" for v in row) for row in R)
            lines.append(f"{robot.config.name}/{arm.name}: ee_link {arm.ee_link}, tcp_offset {arm.tcp_offset:g} m "
                         f"along +{arm.ee_axis}, R_ee_graspnet [{rows}], home {np.round(arm.home, 3).tolist()}")
    return lines


def write_sheet(source: ViewSource, path: Path, q: Sequence[float] | None = None, collision: bool = False) -> Path:
    """Render the sheet of ``source`` (first arm at ``q`` or home) into the PNG ``path``."""
    checked = source.load()
    scene = StillScene.of_robot(checked, q) if isinstance(checked, CheckedRobot) else StillScene.of_task(checked, q)
    with scene:
        sheet = robot_sheet(scene, header_lines(source, source.robots(checked)), collision=collision)
    path.parent.mkdir(parents=True, exist_ok=True)
    sheet.save(path)
    return path
