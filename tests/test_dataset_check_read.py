"""A dataset frame on a divergence check's step takes the arm's joint states and the gripper's
opening from the check's read (``World.checked_joint_states``): the recorded arrays are the same
as reading PyBullet again, at the default 20 Hz (every frame on a check) and at 30 Hz (frames off
the grid are checked by the recorder first)."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pybullet
import pytest
from _cli import ROOT

from robocfg.checks import load_task
from robocfg.datasets.sink import DatasetSink
from robocfg.engine import RunOptions, open_session
from robocfg.sim.world import World


def _record(tmp_path, fps: float, shared: bool, monkeypatch) -> tuple[dict[str, np.ndarray], int]:
    """(float arrays of episode 1's demo, getJointStates calls while recording it)."""
    task = load_task(ROOT / "robocfg/data/tasks/pick_place.yaml")
    task = dataclasses.replace(task, config=task.config.model_copy(update={"cameras": []}))
    out = tmp_path / f"ds_{fps:g}_{shared}"
    sink = DatasetSink(out, "hdf5", task, fps=fps, keep="all", extra_info={"task_path": "pick_place.yaml", "seed": 0})
    if not shared:
        monkeypatch.setattr(World, "checked_joint_states", lambda self, robot: None)
    calls = [0]
    real = pybullet.getJointStates

    def counted(*a, **k):
        calls[0] += 1
        return real(*a, **k)

    with open_session(task, RunOptions(seed=0, sink=sink)) as session:
        monkeypatch.setattr(pybullet, "getJointStates", counted)
        record = session.run(1)
        monkeypatch.setattr(pybullet, "getJointStates", real)
    monkeypatch.undo()
    sink.close()
    assert record.success
    arrays: dict[str, np.ndarray] = {}
    with h5py.File(out / "data.hdf5") as f:
        f["data/demo_0"].visititems(lambda name, obj: arrays.__setitem__(name, obj[()])
                                    if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" else None)
    return arrays, calls[0]


@pytest.mark.parametrize("fps", [20.0, 30.0])
def test_frames_from_the_check_read_are_the_frames_read_again(tmp_path, monkeypatch, fps):
    shared, shared_calls = _record(tmp_path, fps, True, monkeypatch)
    direct, direct_calls = _record(tmp_path, fps, False, monkeypatch)
    assert shared.keys() == direct.keys() and any(k.startswith("obs/") for k in shared)
    for name, a in direct.items():
        assert np.array_equal(shared[name], a), name  # bit for bit
    frames = len(direct["actions"])
    assert frames > 20
    assert direct_calls - shared_calls >= 2 * (frames - 1)  # joints and opening read once fewer per frame but the first
