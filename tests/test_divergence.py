"""A divergence in the middle of a recorded pick-place episode (a NaN object velocity, injected
just before a frame): the episode fails with phase and reason at the frame's step, and no recorded
frame shows the diverged state — at the default 20 Hz, divergence checks and dataset frames fall on
the same steps (``World`` checks every 50 ms of simulated time), the check first; at a rate off
that grid the recorder checks its frames itself."""

from __future__ import annotations

import dataclasses

import h5py
import numpy as np
import pybullet
import pytest
from _cli import ROOT

from robocfg.checks import load_task
from robocfg.datasets.recorder import steps_per_frame
from robocfg.datasets.sink import DatasetSink
from robocfg.engine import RunOptions, open_session


def _float_arrays(group: h5py.Group) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}

    def visit(name: str, obj: object) -> None:  # (a value returned would end the visit)
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
            out[name] = obj[()]

    group.visititems(visit)
    return out


@pytest.mark.parametrize(("fps", "at"), [(20.0, 311), (30.0, 303)])  # 303: before frame step 304, off the check grid
def test_divergence_mid_episode_fails_it_and_records_no_diverged_frame(tmp_path, monkeypatch, fps, at):
    task = load_task(ROOT / "robocfg/data/tasks/pick_place.yaml")
    task = dataclasses.replace(task, config=task.config.model_copy(update={"cameras": []}))
    sink = DatasetSink(tmp_path / "ds", "hdf5", task, fps=fps, keep="all",
                       extra_info={"task_path": "pick_place.yaml", "seed": 0})
    injected: list[int] = []
    with open_session(task, RunOptions(seed=0, sink=sink)) as session:
        world = session.world
        n = steps_per_frame(world.dt, fps)
        assert world.check_every == steps_per_frame(world.dt, 20.0) == 12  # a check at every frame of a 20 Hz dataset
        real_step = pybullet.stepSimulation

        def step(*a, **k):  # the recorded episode's loops count a step right after it (per step)
            real_step(*a, **k)
            s = world.steps + 1
            if not injected and s >= 300 and s % n == n - 1 and "cube" in world.bodies:
                pybullet.resetBaseVelocity(world.bodies["cube"], [float("nan"), 0.0, 0.0], [0.0, 0.0, 0.0],
                                           physicsClientId=world.client)
                injected.append(s)

        monkeypatch.setattr(pybullet, "stepSimulation", step)
        record = session.run(0)
        monkeypatch.undo()
    sink.close()
    assert injected == [at]  # the step before a frame's step (at 20 Hz, 312: no check fell there at a 20 ms period)
    assert not record.success and record.failed_phase == "physics"
    assert record.reason == f"physics diverged at t = {(at + 1) / 240:.3f} s (body 'cube' speed nan m/s)"
    with h5py.File(tmp_path / "ds" / "data.hdf5") as f:
        arrays = _float_arrays(f["data/demo_0"])
    assert "actions" in arrays and any(k.startswith("obs/") for k in arrays)
    assert len(arrays["actions"]) == (at + 1) // n  # frames up to the one before the diverged step
    for name, a in arrays.items():
        assert np.isfinite(a).all(), name
