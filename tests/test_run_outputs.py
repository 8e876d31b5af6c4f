"""Run outputs: paths checked before simulating, ``--json -``, atomic reports, SIGINT, the report
schema (issue: reports survive faults)."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest
from _cli import ROOT, run_main
from test_golden_reports import GOLDEN, _assert_same

from robocfg.cli.common import write_json
from robocfg.cli.episodes import failure_lines

ROBOCFG = [sys.executable, "-m", "robocfg"]


@pytest.mark.parametrize(("args", "option", "says"), [
    (["--json", "{tmp}/missing/r.json"], "--json", "does not exist"),
    (["--json", "{tmp}/newdir/"], "--json", "is a folder"),
    (["--json", "{tmp}"], "--json", "is a folder"),
    (["--json", "{tmp}/r.txt"], "--json", "must end in .json"),
    (["--record", "{tmp}/a.avi"], "--record", "must end in .gif or .mp4 or .png"),
    (["--record", "{tmp}/ro/a.gif"], "--record", "not writable"),
    (["--record", "{tmp}/a.gif", "--record-episode", "5", "-n", "1"], "--record-episode", "episode 5 does not run"),
])
def test_bad_output_paths_exit_2_before_simulating(args, option, says, tmp_path, capsys, monkeypatch):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    if os.access(ro, os.W_OK) and "ro/" in " ".join(args):  # root ignores permission bits
        ro.chmod(0o700)
        monkeypatch.setattr("robocfg.cli.common._can_create_in", lambda folder: folder != ro)
    argv = ["run", "pick-place", *[a.format(tmp=tmp_path) for a in args], "-q"]
    code, out, err = run_main(argv, capsys, monkeypatch)
    assert code == 2, (out, err)
    assert option in err and says in err and "Traceback" not in err
    assert "placed" not in out  # nothing was simulated
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ro"]  # and nothing written


def test_json_dash_writes_the_report_to_stdout(capsys, monkeypatch):
    code, out, err = run_main(["robots", "--json", "-"], capsys, monkeypatch)
    assert code == 0, err
    rows = {r["name"]: r for r in json.loads(out)}  # stdout holds only the JSON; the table went to stderr
    assert rows["panda"]["grippers"] == ["parallel"] and "panda" in err
    assert not (ROOT / "-").exists()


def test_write_json_is_atomic_under_two_writers_and_a_reader(tmp_path):
    """Two processes rewrite the same report 150 times each with different, large payloads; a
    reader polling the file must always parse one whole payload, never a torn mix."""
    target = tmp_path / "r.json"
    write_json(target, {"writer": "init", "data": []})
    code = ("import sys; from pathlib import Path; from robocfg.cli.common import write_json\n"
            "w = sys.argv[1]\n"
            "for i in range(150): write_json(Path(sys.argv[2]), {'writer': w, 'i': i, 'data': [w * 40] * 2000})\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    writers = [subprocess.Popen([sys.executable, "-c", code, w, str(target)], env=env) for w in ("a", "b")]
    reads = 0
    while any(w.poll() is None for w in writers) or reads == 0:
        doc = json.loads(target.read_text())
        assert doc["writer"] in ("init", "a", "b")
        if doc["writer"] != "init":
            assert doc["data"] == [doc["writer"] * 40] * 2000
        reads += 1
    assert all(w.wait() == 0 for w in writers)
    assert json.loads(target.read_text())["i"] == 149
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]  # no temporary file left behind


def test_write_json_writes_non_finite_numbers_as_null(tmp_path):
    # a diverged body's pose is NaN: the report must stay JSON that strict readers accept
    import dataclasses

    import numpy as np

    @dataclasses.dataclass
    class Row:
        final: list[float]
        tilt: float

    target = tmp_path / "r.json"
    write_json(target, {"episodes": [Row([float("nan"), 0.5, float("inf")], np.float32("nan"))],
                        "k": (1, -float("inf")), "ok": np.bool_(True), "n": np.int64(3)})
    text = target.read_text()
    assert "NaN" not in text and "Infinity" not in text
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"non-standard JSON token {c}"))
    assert doc == {"episodes": [{"final": [None, 0.5, None], "tilt": None}], "k": [1, None], "ok": True, "n": 3}


def test_sigint_writes_the_finished_episodes_marked_interrupted(tmp_path):
    """SIGINT during episode 0 of 3: episode 0 finishes, the report holds it (identical to the same
    episode of an uninterrupted run), says interrupted, and the exit code is 130."""
    report, gif = tmp_path / "r.json", tmp_path / "a.gif"
    report.write_text('{"stale": true}')
    proc = subprocess.Popen([*ROBOCFG, "run", "pick-place", "-n", "3", "--seed", "7", "--json", str(report),
                             "--record", str(gif), "-q"], cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    deadline = time.monotonic() + 120
    while not gif.exists():  # the recorder opens its file when episode 0 starts
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    doc = json.loads(report.read_text())
    assert doc["interrupted"] is True and doc["schema_version"] == 2
    assert 1 <= len(doc["episodes"]) < 3
    golden = json.loads((GOLDEN / "pick-place.json").read_text())
    _assert_same(doc["episodes"][0], golden["episodes"][0])
    assert err.count("interrupted (SIGINT)") == 1 and "Traceback" not in err


def test_report_positions_and_angles_do_not_share_a_field():
    doc = json.loads((GOLDEN / "pick-place.json").read_text())
    e = doc["episodes"][0]
    assert len(e["object_start"]) == len(e["object_final"]) == 3  # both x, y, z in metres
    assert e["object_start"][2] == pytest.approx(e["object_final"][2], abs=0.01)  # spawned and placed on the table
    assert isinstance(e["object_start_yaw_deg"], float)


def test_schema_command_describes_the_reports(capsys, monkeypatch):
    for kind, episode in (("report-pick-place", "EpisodeResult"), ("report-grasp", "GraspEpisode")):
        code, out, err = run_main(["schema", kind], capsys, monkeypatch)
        assert code == 0, err
        schema = json.loads(out)
        assert {"schema_version", "interrupted", "episodes"} <= set(schema["properties"])
        assert "object_start_yaw_deg" in schema["$defs"][episode]["properties"]


def test_quiet_failure_lines_count_each_distinct_reason():
    from robocfg.runners.pick_place_report import EpisodeResult

    def ep(i, phase, reason):
        return EpisodeResult(i, 7 + i, phase is None, phase, reason, [0, 0, 0], 0.0, [0, 0], [0, 0, 0],
                             None, None, None, 0.1, 1.0, 0.0, 0)

    eps = [ep(0, "approach", "IK did not converge"), ep(1, None, "placed"),
           ep(2, "approach", "IK did not converge"), ep(3, "place", "object tilted 40.0°")]
    assert failure_lines(eps) == ["2 × approach: IK did not converge", "1 × place: object tilted 40.0°"]


def test_one_phase_failed_error_for_moves_episodes_and_runs():
    from robocfg.errors import PhaseFailed, PhysicsDiverged, RunFailed
    from robocfg.motion.moves import MoveFailed
    from robocfg.runners.grasp import EpisodeFailed

    assert MoveFailed is PhaseFailed and EpisodeFailed is PhaseFailed
    exc = PhysicsDiverged(1.25, "body 'cube' speed 90 m/s")
    assert isinstance(exc, RunFailed) and isinstance(exc, PhaseFailed)
    assert (exc.phase, exc.reason) == ("physics", "physics diverged at t = 1.250 s (body 'cube' speed 90 m/s)")
