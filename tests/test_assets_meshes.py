"""Mesh vertices read for the URDF checks (OBJ/STL without importing trimesh) match trimesh's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pybullet_data
import pytest
import trimesh

from robocfg.assets.meshes import read_vertices

DATA = Path(pybullet_data.getDataPath())


def _unique(v: np.ndarray) -> np.ndarray:
    return np.unique(np.round(v, 6), axis=0)


@pytest.mark.parametrize("mesh", ["franka_panda/meshes/collision/finger.obj", "cube.obj"])
def test_obj_vertices_match_trimesh(mesh):
    ours = read_vertices(DATA / mesh)
    theirs = trimesh.load(DATA / mesh, force="mesh", process=False).vertices
    assert len(ours) > 0
    assert np.array_equal(_unique(ours), _unique(theirs))


@pytest.mark.parametrize("encoding", ["binary", "ascii"])
def test_stl_vertices_match_trimesh(tmp_path, encoding):
    box = trimesh.creation.box([0.1, 0.2, 0.3], transform=trimesh.transformations.translation_matrix([0.5, 0, 1]))
    path = tmp_path / f"box_{encoding}.stl"
    path.write_bytes(trimesh.exchange.stl.export_stl(box) if encoding == "binary"
                     else trimesh.exchange.stl.export_stl_ascii(box).encode())
    ours = read_vertices(path)
    assert len(ours) == 3 * len(box.faces)  # one vertex per facet corner, as the file stores them
    assert np.allclose(_unique(ours), _unique(box.vertices), atol=1e-6)


def test_other_formats_go_through_trimesh(tmp_path):
    path = tmp_path / "box.ply"
    trimesh.creation.box([0.1, 0.1, 0.1]).export(path)
    assert np.allclose(np.abs(read_vertices(path)), 0.05)
