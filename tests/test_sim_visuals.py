"""Multi-material OBJ visuals are split so that each material keeps its colour in PyBullet."""

from __future__ import annotations

import numpy as np
import pybullet as p
from _sim_helpers import DATA, make_task

from robocfg.sim.visuals import split_by_material
from robocfg.sim.world import World

MTL = "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\nd 0.5\n"
OBJ = """mtllib two.mtl
v 0 0 0
v 0.05 0 0
v 0 0.05 0
v 0 0 0.05
usemtl red
f 1 2 3
usemtl blue
f -4 -3 -1
f 1 3 4
"""


def _write(tmp_path):
    (tmp_path / "two.mtl").write_text(MTL)
    (tmp_path / "two.obj").write_text(OBJ)
    return tmp_path / "two.obj"


def test_split_by_material_reindexes_and_colours(tmp_path):
    parts = split_by_material(_write(tmp_path))
    assert [c for _, c in parts] == [(1.0, 0.0, 0.0, 1.0), (0.0, 0.0, 1.0, 0.5)]
    red = parts[0][0].read_text().splitlines()
    assert red == ["v 0 0 0", "v 0.05 0 0", "v 0 0.05 0", "f 1 2 3"]
    blue = parts[1][0].read_text().splitlines()
    # faces (−4 −3 −1) = (1 2 4) and (1 3 4); new vertex order 1, 2, 4, 3
    assert [ln for ln in blue if ln.startswith("f")] == ["f 1 2 3", "f 1 4 3"]
    assert blue[:4] == ["v 0 0 0", "v 0.05 0 0", "v 0 0 0.05", "v 0 0.05 0"]
    (tmp_path / "one.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n")
    assert split_by_material(tmp_path / "one.obj") is None


def test_world_colours_each_material(tmp_path):
    _write(tmp_path)
    urdf = (DATA / "sim_suction.urdf").read_text().replace(
        '<visual><geometry><box size="0.05 0.05 0.05"/></geometry><material name="blue"><color rgba="0.2 0.3 0.8 1"/></material></visual>',
        '<visual><geometry><mesh filename="two.obj"/></geometry></visual>')
    (tmp_path / "robot.urdf").write_text(urdf)
    robot_yaml = (DATA / "sim_suction_robot.yaml").read_text().replace("urdf: sim_suction.urdf", "urdf: robot.urdf")
    (tmp_path / "robot.yaml").write_text(robot_yaml)
    with World(make_task(tmp_path, tmp_path / "robot.yaml")) as w:
        link = w.robot.link("carriage")
        colours = [tuple(np.round(v[7], 3)) for v in p.getVisualShapeData(w.robot.body_id, physicsClientId=w.client)
                   if v[1] == link]
        assert sorted(colours) == [(0.0, 0.0, 1.0, 0.5), (1.0, 0.0, 0.0, 1.0)]
