"""Episodes spread over worker processes: the report and the dataset are those of one process,
whatever the worker count; a worker killed with SIGKILL is reported with the episodes it took,
the others are kept, and the run ends (exit 1) instead of hanging."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import psutil
import pytest
from _cli import ROOT, run_main
from _parallel import files_of, run_json, small_camera_task

FPS = "10"  # divides the 240 Hz physics rate; few rendered frames keep the test quick


@pytest.mark.parametrize(("fmt", "episodes", "actions"), [("lerobot", 4, "ee_delta"), ("hdf5", 3, "both")])
def test_two_workers_give_the_report_and_dataset_of_one(fmt, episodes, actions, tmp_path, capsys, monkeypatch):
    task = str(small_camera_task(tmp_path))  # depth and EE-delta actions go through the shard merge too
    common = ["run", "pick-place", task, "-n", str(episodes), "--seed", "5", "--dataset-fps", FPS,
              "--dataset-format", fmt, "--keep", "all", "--dataset-actions", actions]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    two = run_json([*common, "--workers", "2", "--dataset", str(tmp_path / "two")], tmp_path, "two", capsys, monkeypatch)
    assert [e["index"] for e in two["episodes"]] == list(range(episodes))
    assert one == two
    a, b = files_of(tmp_path / "one"), files_of(tmp_path / "two")
    assert list(a) == list(b) and not any(".shards" in name for name in b)  # shards merged, then removed
    for name in a:
        assert a[name] == b[name], f"{name} differs"  # videos, parquet and HDF5 byte for byte


def test_grasp_datasets_are_the_same_on_two_workers(tmp_path, capsys, monkeypatch):
    """The engine records every kind the same way, so a grasp run's report and dataset (one
    instruction per episode's object) do not depend on the worker count either."""
    common = ["run", "grasp", "-n", "2", "--seed", "5", "--dataset-fps", FPS, "--keep", "all"]
    one = run_json([*common, "--workers", "1", "--dataset", str(tmp_path / "one")], tmp_path, "one", capsys, monkeypatch)
    two = run_json([*common, "--workers", "2", "--dataset", str(tmp_path / "two")], tmp_path, "two", capsys, monkeypatch)
    assert one == two
    a, b = files_of(tmp_path / "one"), files_of(tmp_path / "two")
    assert list(a) == list(b) and "meta/tasks.parquet" in a
    for name in a:
        assert a[name] == b[name], f"{name} differs"


def test_a_killed_worker_is_reported_with_its_episodes_and_the_run_ends(tmp_path):
    """kill -9 of one worker mid-run: exit 1, the JSON holds every other episode and names the
    lost ones with the signal; nothing hangs (the timeout would fail the test)."""
    report = tmp_path / "r.json"
    proc = subprocess.Popen([sys.executable, "-m", "robocfg", "run", "pick-place", "-n", "6", "--workers", "2",
                             "--json", str(report), "-q"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    victim = _wait_for_workers(proc.pid, 2)[0]
    victim.send_signal(signal.SIGKILL)
    _out, err = proc.communicate(timeout=600)
    assert proc.returncode == 1, err
    doc = json.loads(report.read_text())
    lost = [k for x in doc["lost_episodes"] for k in x["episodes"]]
    assert lost and all("SIGKILL" in x["reason"] for x in doc["lost_episodes"])
    done = [e["index"] for e in doc["episodes"]]
    assert sorted(done + lost) == list(range(6)) and not set(done) & set(lost)
    assert doc["summary"]["episodes"] == len(done)
    assert "lost episode" in err and "SIGKILL" in err


def _wait_for_workers(pid: int, n: int, timeout: float = 120.0) -> list[psutil.Process]:
    """The worker processes of the CLI process ``pid``: children of its fork server, which has
    the CLI as parent; found once ``n`` of them run."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            kids = psutil.Process(pid).children()
            workers = [w for k in kids for w in k.children()]
        except psutil.NoSuchProcess:
            break
        if len(workers) >= n:
            return workers
        time.sleep(0.05)
    raise AssertionError(f"no {n} workers under process {pid}")


def test_workers_option_is_checked(capsys, monkeypatch):
    code, _, err = run_main(["run", "pick-place", "--workers", "0"], capsys, monkeypatch)
    assert code == 2 and "--workers" in err
    code, _, err = run_main(["run", "pick-place", "--executor", "dask"], capsys, monkeypatch)
    assert code == 2 and "choose local or ray" in err
    code, _, err = run_main(["run", "pick-place", "--gui", "--workers", "2", "-n", "2"], capsys, monkeypatch)
    assert code == 2 and "--gui" in err
