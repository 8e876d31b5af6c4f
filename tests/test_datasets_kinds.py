"""--dataset on the kinds beyond pick-place: pick-place-many (several objects in the environment
state, replayed through its runner, the same dataset on 1 and 2 workers)."""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import yaml
from _cli import ROOT
from _parallel import files_of, run_json

from robocfg.datasets.replay import replay_episode


def _two_objects(tmp) -> str:
    """The shipped pick-place-many task with its first two objects only (a quicker episode)."""
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place_many.yaml").read_text())
    doc["pick_place_many"]["objects"] = doc["pick_place_many"]["objects"][:2]
    path = tmp / "two_objects.yaml"
    path.write_text(yaml.safe_dump(doc, sort_keys=False))
    return str(path)


def test_pick_place_many_records_every_object_and_replays(tmp_path, capsys, monkeypatch):
    task = _two_objects(tmp_path)
    common = ["run", "pick-place-many", task, "-n", "2", "--dataset-fps", "10", "--keep", "all"]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    two = run_json([*common, "--workers", "2", "--dataset", str(tmp_path / "two")], tmp_path, "two", capsys, monkeypatch)
    assert one == two and [e["success"] for e in one["episodes"]] == [True, True]
    assert files_of(tmp_path / "one") == files_of(tmp_path / "two")

    root = tmp_path / "one"
    info = json.loads((root / "meta/info.json").read_text())
    names = info["features"]["observation.environment_state"]["names"]
    assert names[:3] == ["object.red.x", "object.red.y", "object.red.z"] and names[7] == "object.green.x"
    assert len(names) == 14 and "withdraw" in info["robocfg"]["phases"]
    tasks = pq.read_table(root / "meta/tasks.parquet").to_pydict()["__index_level_0__"]
    assert tasks == ["put the red box and the green box into bin_b"]
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    env = np.asarray(data["observation.environment_state"].to_pylist())
    ep0 = env[data["episode_index"].to_numpy() == 0]
    # each object's own track: red and green start 12 cm apart in x and both end in bin_b (y > 0)
    assert abs((ep0[0, 7] - ep0[0, 0]) - 0.12) < 0.03 and ep0[-1, 1] > 0.1 and ep0[-1, 8] > 0.1
    final = [ep["objects"] for ep in one["episodes"]][1]

    r = replay_episode(root, 1)
    assert r.matches and r.replayed_reason == "2 objects placed"
    assert np.allclose(np.reshape(r.replayed_object, (2, 3)), [o["final"] for o in final], atol=1e-3)
    # the gripper never closing: no object leaves bin_a, and replay says so
    path = root / "data/chunk-000/file-000.parquet"
    act = np.asarray(data["action"].to_pylist(), np.float32)
    act[:, -1] = 1.0
    col = pa.FixedSizeListArray.from_arrays(pa.array(act.reshape(-1)), act.shape[1])
    pq.write_table(data.set_column(data.schema.get_field_index("action"), "action", col), path)
    r = replay_episode(root, 1)
    assert not r.matches and not r.replayed_success and r.replayed_reason.startswith("red: place")
