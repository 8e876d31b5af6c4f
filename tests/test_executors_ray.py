"""``--executor ray`` against a local Ray started here: the same report and the same dataset,
byte for byte, as one process."""

from __future__ import annotations

import ray
from _parallel import files_of, run_json, small_camera_task


def test_ray_actors_give_the_report_and_dataset_of_one_process(tmp_path, capsys, monkeypatch):
    task = str(small_camera_task(tmp_path))
    common = ["run", "pick-place", task, "-n", "3", "--seed", "2", "--dataset-fps", "10", "--keep", "all"]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    ray.init(num_cpus=2, include_dashboard=False)
    try:
        on_ray = run_json([*common, "--executor", "ray", "--workers", "2", "--dataset", str(tmp_path / "ray")],
                          tmp_path, "ray", capsys, monkeypatch)
    finally:
        ray.shutdown()
    assert one == on_ray
    a, b = files_of(tmp_path / "one"), files_of(tmp_path / "ray")
    assert list(a) == list(b)
    for name in a:
        assert a[name] == b[name], f"{name} differs"
