"""Concave finger meshes are decomposed into convex parts (PyBullet collides with a mesh's hull)."""

from __future__ import annotations

import trimesh

from robocfg.sim.concave import convex_parts


def _u_shape(path):
    """A U of three touching boxes (4 cm wide throat): its hull has about twice its volume."""
    parts = [trimesh.creation.box((0.02, 0.02, 0.06), trimesh.transformations.translation_matrix((-0.03, 0, 0.03))),
             trimesh.creation.box((0.02, 0.02, 0.06), trimesh.transformations.translation_matrix((0.03, 0, 0.03))),
             trimesh.creation.box((0.04, 0.02, 0.02), trimesh.transformations.translation_matrix((0.0, 0, 0.01)))]
    trimesh.util.concatenate(parts).export(str(path))


def test_a_concave_mesh_is_decomposed_once_a_convex_one_is_left_alone(tmp_path):
    u = tmp_path / "u_jaw.obj"
    _u_shape(u)
    out = convex_parts(u)
    assert out is not None and out.suffix == ".obj"
    groups = [ln for ln in out.read_text().splitlines() if ln.startswith("o ")]
    assert len(groups) >= 2  # one object per convex part: PyBullet loads them as a compound
    hulls = trimesh.load(str(out), force="mesh").split(only_watertight=False)
    assert sum(h.convex_hull.volume for h in hulls) < 0.8 * trimesh.load(str(u), force="mesh").convex_hull.volume
    assert convex_parts(u) == out  # cached by content
    box = tmp_path / "box.obj"
    trimesh.creation.box((0.02, 0.02, 0.06)).export(str(box))
    assert convex_parts(box) is None
