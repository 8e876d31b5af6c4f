"""``run <kind> --resume r.json`` (issue 14): an interrupted batch run is finished by running only
its missing episodes, and the whole report equals an uninterrupted run's byte for byte; a report
of another task, robot, arm, seed or option set is refused before simulating."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import pytest
from _cli import ROOT, run_main
from test_golden_reports import GOLDEN

from robocfg.engine.records import RecordMismatch, episode_record_type, records_from_json
from robocfg.runners.grasp_report import GraspReport
from robocfg.runners.pick_place_report import PickPlaceReport

ROBOCFG = [sys.executable, "-m", "robocfg"]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}
RUN = ["run", "pick-place", "-n", "4", "--seed", "7", "-q"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(the partial report of a run stopped by SIGINT once episode 1 began, the report of the same
    run left alone)."""
    tmp = tmp_path_factory.mktemp("resume")
    partial, gif, straight = tmp / "partial.json", tmp / "ep1.gif", tmp / "straight.json"
    proc = subprocess.Popen([*ROBOCFG, *RUN, "--workers", "1", "--json", str(partial), "--record", str(gif),
                             "--record-episode", "1"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=ENV)
    deadline = time.monotonic() + 120
    while not gif.exists():  # the recorder opens its file when episode 1 starts: episode 0 is done
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert out.startswith("interrupted: panda placed 2/2 (100.0%)"), out  # not "ok": the run did not finish
    done = subprocess.run([*ROBOCFG, *RUN, "--workers", "1", "--json", str(straight)], cwd=ROOT, env=ENV,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return partial, straight


def test_an_interrupted_report_carries_what_resuming_checks(runs):
    partial, straight = runs
    doc = json.loads(partial.read_text())
    assert doc["interrupted"] is True and [e["index"] for e in doc["episodes"]] == [0, 1]
    block = doc["resume"]
    assert (block["kind"], block["robot"], block["episodes"], block["seed"], block["arm"]) == \
        ("pick_place", "panda", 4, 7, "arm")
    assert block["fingerprint"].startswith("sha256:")
    assert "resume" not in json.loads(straight.read_text())  # a finished run's report is unchanged


@pytest.mark.parametrize("workers", ["1", "2"])
def test_resume_runs_the_missing_episodes_and_equals_the_straight_run(runs, workers, tmp_path):
    partial, straight = runs
    report = tmp_path / "r.json"
    shutil.copy(partial, report)
    # -n and --seed are not given again: they come from the partial report
    done = subprocess.run([*ROBOCFG, "run", "pick-place", "--resume", str(report), "--workers", workers, "-q"],
                          cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert report.read_bytes() == straight.read_bytes()


@pytest.mark.parametrize(("extra", "says"), [
    (["--seed", "8"], "was run with --seed 7, this run has --seed 8"),
    (["--arm", "arm", "--set", "pick_place.lift_height=0.2"], "was run with another task or robot"),
    (["--robot", "xarm6"], "is a report of robot 'panda', this run is of robot 'xarm6' (--robot)"),
    (["-n", "1"], "holds episode 1, beyond -n 1"),
])
def test_a_report_of_another_run_is_refused_before_simulating(runs, extra, says, capsys, monkeypatch):
    monkeypatch.setattr("robocfg.sim.world.World.__init__", lambda *a, **k: pytest.fail("a world was built"))
    code, out, err = run_main(["run", "pick-place", "--resume", str(runs[0]), *extra, "-q"], capsys, monkeypatch)
    assert code == 2, (out, err)
    assert err.strip().startswith(f"--resume {runs[0]}: {says}"), err


def test_resume_refusals_of_files_and_kinds(runs, tmp_path, capsys, monkeypatch):
    partial, straight = runs
    monkeypatch.setattr("robocfg.sim.world.World.__init__", lambda *a, **k: pytest.fail("a world was built"))
    cases = [
        (["run", "pick-place", "--resume", str(straight)], f"--resume {straight}: is the report of a run that "
                                                           "finished: nothing to resume"),
        (["run", "pick-place", "--resume", str(tmp_path / "none.json")], f"--resume {tmp_path / 'none.json'}: "
                                                                         "no such file"),
        (["run", "grasp", "--resume", str(partial)], f"--resume {partial}: is a 'run pick-place' report, "
                                                     "not 'run grasp'"),
        (["run", "pick-place", "--resume", str(partial), "--dataset", str(tmp_path / "ds")],
         "--dataset: cannot be continued by --resume"),
        (["run", "pick-place", "--resume", str(partial), "--record", str(tmp_path / "a.gif")],
         "--record-episode: episode 0 finished before the interruption"),
    ]
    for args, says in cases:
        code, out, err = run_main([*args, "-q"], capsys, monkeypatch)
        assert code == 2 and err.startswith(says) and "Traceback" not in err, (args, out, err)


@pytest.mark.parametrize("kind", ["gripper", "trajectory", "follow-target"])
def test_one_episode_kinds_do_not_offer_resume(kind, capsys, monkeypatch):
    code, _out, err = run_main(["run", kind, "--resume", "r.json"], capsys, monkeypatch)
    assert code == 2 and "No such option: --resume" in err


@pytest.mark.parametrize(("report_type", "name"), [(PickPlaceReport, "pick-place"), (GraspReport, "grasp")])
def test_episode_records_read_back_from_json_write_the_same_bytes(report_type, name):
    from robocfg.cli.common import _default

    episodes = json.loads((GOLDEN / f"{name}.json").read_text())["episodes"]
    records = records_from_json(episode_record_type(report_type), episodes)
    assert json.dumps(records, default=_default, indent=2) == json.dumps(episodes, indent=2)
    broken = [dict(episodes[0], success="yes")]
    with pytest.raises(RecordMismatch, match=r"episodes\[0\]\.success: expected bool"):
        records_from_json(episode_record_type(report_type), broken)


def test_run_batch_keeps_resumed_records_in_place_when_stopped_again():
    """Episodes 0 and 3 came from the interrupted run; a stop after episode 1 still reports 0, 1, 3
    (in index order), and episode 1 was the only one run."""
    from dataclasses import dataclass

    from robocfg.engine import RunOptions, run_batch

    @dataclass
    class Rec:
        index: int
        success: bool = True
        failed_phase: str | None = None
        reason: str = ""

    ran: list[int] = []

    class Session:
        def run(self, k):
            ran.append(k)
            return Rec(k)

    options = RunOptions(episodes=5, resumed=(Rec(3), Rec(0)), should_stop=lambda: len(ran) >= 1)
    records, interrupted = run_batch(Session(), options)  # type: ignore[arg-type]
    assert interrupted and ran == [1] and [r.index for r in records] == [0, 1, 3]
    records, interrupted = run_batch(Session(), RunOptions(episodes=5, resumed=(Rec(3), Rec(0))))
    assert not interrupted and ran == [1, 1, 2, 4] and [r.index for r in records] == [0, 1, 2, 3, 4]
    with pytest.raises(ValueError, match="resumed episode 7"):
        run_batch(Session(), RunOptions(episodes=5, resumed=(Rec(7),)))
