"""--dataset-actions: EE-delta actions (the commanded TCP pose change per frame, robot base frame)
beside or instead of the joint targets; replay always drives with the joint targets."""

from __future__ import annotations

import json

import h5py
import numpy as np
import pyarrow.parquet as pq
import yaml
from _cli import ROOT, run_main
from scipy.spatial.transform import Rotation

from robocfg.datasets.replay import replay_episode


def _state_only_task(tmp) -> str:
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    doc.pop("cameras")
    doc["robots"][0]["position"] = [0.1, -0.05, 0.02]  # base frame != world frame
    doc["robots"][0]["euler_deg"] = [0.0, 0.0, 30.0]
    path = tmp / "state_only.yaml"
    path.write_text(yaml.safe_dump(doc))
    return str(path)


def _rows(table, key) -> np.ndarray:
    return np.asarray(table[key].to_pylist(), np.float64)


def test_ee_delta_actions_sum_to_the_tcp_path_the_arm_followed(tmp_path, capsys, monkeypatch):
    task, root = _state_only_task(tmp_path), tmp_path / "both"
    code, _, err = run_main(["run", "pick-place", task, "--dataset", str(root), "--dataset-actions", "both",
                             "--dataset-fps", "10", "-q"], capsys, monkeypatch)
    assert code == 0, err
    info = json.loads((root / "meta/info.json").read_text())
    assert info["robocfg"]["actions"] == "both"
    feat = info["features"]["action.ee_delta"]
    assert feat["shape"] == [7] and feat["names"][:3] == ["tcp.dx", "tcp.dy", "tcp.dz"]
    assert info["features"]["action"]["shape"] == [8]  # the joint targets stay the action
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    ee, joint = _rows(data, "action.ee_delta"), _rows(data, "action")
    names = info["features"]["observation.state"]["names"]
    state = _rows(data, "observation.state")
    tcp = state[:, names.index("tcp.x"):names.index("tcp.z") + 1]  # measured, base frame
    quat = state[:, names.index("tcp.qx"):names.index("tcp.qw") + 1]
    assert np.all(ee[0, :6] == 0.0) and np.array_equal(ee[:, 6], joint[:, 7])
    assert np.abs(ee[:, :3]).max() > 0.01  # the TCP really moves between frames
    # action k is reached at frame k + 1: the measured TCP there is the start plus the summed deltas
    # (in the base frame: the robot is mounted turned 30 deg, so world-frame deltas would not match)
    commanded = tcp[0] + np.cumsum(ee[:, :3], axis=0)
    err = np.linalg.norm(tcp[1:] - commanded[:-1], axis=1)
    assert np.median(err) < 0.002 and err.max() < 0.005  # measured: 0.7 mm median, 2.8 mm max
    R = Rotation.from_quat(quat[0])
    rot_err = []
    for k in range(len(ee) - 1):
        R = Rotation.from_rotvec(ee[k, 3:6]) * R
        rot_err.append((Rotation.from_quat(quat[k + 1]) * R.inv()).magnitude())
    assert np.median(rot_err) < 0.01

    ee_only = tmp_path / "ee"
    code, _, err = run_main(["run", "pick-place", task, "--dataset", str(ee_only), "--dataset-actions", "ee_delta",
                             "--dataset-fps", "10", "--dataset-format", "hdf5", "-q"], capsys, monkeypatch)
    assert code == 0, err
    with h5py.File(ee_only / "data.hdf5", "r") as f:
        demo = f["data/demo_0"]
        assert json.loads(f["data"].attrs["env_args"])["env_kwargs"]["actions"] == "ee_delta"
        np.testing.assert_array_equal(demo["actions"][()], ee.astype(np.float32))  # same run, same deltas
        np.testing.assert_array_equal(demo["actions_joint"][()], joint.astype(np.float32))
    r = replay_episode(ee_only, 0)  # from the joint targets
    assert r.matches and r.replayed_success and r.distance < 1e-6
