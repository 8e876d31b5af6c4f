"""``robocfg validate`` / ``inspect`` / ``robots`` / ``schema`` end to end.

The bad-input corpus (tests/bad/*.yaml) declares what each file must produce with leading
``# expect: TEXT`` comments: the run exits 2, prints ``FILE:LINE[:COL]: ...`` lines, one of
which contains each TEXT, and never a Python traceback.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from _cli import run_main

from robocfg.cli.app import main

ROOT = Path(__file__).resolve().parent.parent
BAD = ROOT / "tests" / "bad"
DATA = ROOT / "tests" / "data"
CORPUS = sorted(BAD.glob("*.yaml"))
LOC_LINE = re.compile(r"^[^:]+:\d+(:\d+)?: ")


def expectations(path: Path) -> list[str]:
    text = path.read_bytes().decode("utf-8", errors="replace")
    return [ln[len("# expect: "):].strip() for ln in text.splitlines() if ln.startswith("# expect: ")]


def run_process(args: list[str], **kw) -> subprocess.CompletedProcess:
    """Run the installed ``robocfg`` command as a real process."""
    exe = shutil.which("robocfg", path=str(Path(sys.executable).parent)) or shutil.which("robocfg")
    cmd = [exe] if exe else [sys.executable, "-c", "from robocfg.cli.app import main; main()"]
    return subprocess.run([*cmd, *args], cwd=ROOT, capture_output=True, text=True, timeout=120, **kw)


def assert_bad_output(path: Path, code: int, out: str, err: str) -> None:
    text = out + err
    assert "Traceback" not in text
    assert code == 2, text
    located = [ln for ln in text.splitlines() if LOC_LINE.match(ln)]
    assert located, f"no FILE:LINE message in:\n{text}"
    for want in expectations(path):
        assert any(want in ln for ln in located), f"{want!r} not in:\n" + "\n".join(located)


def test_corpus_is_large_and_declares_expectations():
    assert len(CORPUS) >= 25
    for f in CORPUS:
        assert expectations(f), f"{f.name} has no '# expect:' line"
    assert {"broken.urdf", "missing_mesh.urdf"} <= {p.name for p in (BAD / "urdf").iterdir()}


@pytest.mark.parametrize("path", CORPUS, ids=lambda p: p.stem)
def test_bad_file_in_process(path, capsys, monkeypatch):
    code, out, err = run_main(["validate", str(path.relative_to(ROOT))], capsys, monkeypatch)
    assert_bad_output(path, code, out, err)
    assert "invalid" in out  # the summary table still prints


SUBPROCESS_SAMPLE = ["robot_unknown_key_ee_lnk", "robot_missing_mesh", "task_unknown_robot"]


@pytest.mark.parametrize("stem", SUBPROCESS_SAMPLE)
def test_bad_file_subprocess(stem):
    path = BAD / f"{stem}.yaml"
    r = run_process(["validate", str(path.relative_to(ROOT))])
    assert_bad_output(path, r.returncode, r.stdout, r.stderr)


def test_whole_corpus_directory_in_one_call(tmp_path, capsys, monkeypatch):
    """A directory is walked recursively; one bad file makes the exit code 2."""
    code, out, err = run_main(["validate", "tests/bad", "--json", str(tmp_path / "corpus.json")], capsys, monkeypatch)
    assert code == 2 and "Traceback" not in out + err
    report = json.loads((tmp_path / "corpus.json").read_text())
    assert report["valid"] is False
    assert len(report["files"]) == len(CORPUS)
    assert all(not f["valid"] for f in report["files"])


# ---------------------------------------------------------------- good path


def test_validate_builtins_exit_0_with_table(capsys, monkeypatch):
    code, out, err = run_main(["validate"], capsys, monkeypatch)
    assert code == 0, out + err
    assert "robocfg validate" in out and "panda.yaml" in out and "robot" in out
    assert "invalid" not in out


def test_validate_builtins_subprocess():
    r = run_process(["validate"])
    assert r.returncode == 0, r.stdout + r.stderr
    assert "panda.yaml" in r.stdout


def test_validate_good_test_files(capsys, monkeypatch):
    code, out, err = run_main(["validate", "tests/data"], capsys, monkeypatch)
    assert code == 0, out + err
    for name in ("task_gripper.yaml", "task_pick_place.yaml", "panda_no_gripper.yaml", "panda_off_tcp.yaml"):
        assert name in out


def test_validate_json_report(tmp_path, capsys, monkeypatch):
    out_json = tmp_path / "report.json"
    code, _, _ = run_main(["validate", "robocfg/data/robots/panda.yaml", "tests/data/panda_off_tcp.yaml", "--json", str(out_json)],
                          capsys, monkeypatch)
    assert code == 0
    report = json.loads(out_json.read_text())
    assert report["valid"] is True
    by_name = {Path(f["file"]).name: f for f in report["files"]}
    assert by_name["panda.yaml"]["kind"] == "robot" and by_name["panda.yaml"]["warnings"] == []
    [warning] = by_name["panda_off_tcp.yaml"]["warnings"]
    assert warning["path"] == "arms[0].tcp_offset" and warning["severity"] == "warning" and warning["line"] > 0


def test_strict_turns_warning_into_exit_2(capsys, monkeypatch):
    path = "tests/data/panda_off_tcp.yaml"
    code, out, err = run_main(["validate", path], capsys, monkeypatch)
    assert code == 0
    assert re.search(r"panda_off_tcp\.yaml:\d+:\d+: arms\[0\]\.tcp_offset: warning: ", err)
    code, out, err = run_main(["validate", "--strict", path], capsys, monkeypatch)
    assert code == 2
    assert "Traceback" not in out + err
    assert re.search(r"panda_off_tcp\.yaml:\d+:\d+: arms\[0\]\.tcp_offset: warning: finger-pad midpoint", err)


def test_strict_on_a_task_checks_its_robots_strictly(tmp_path, capsys, monkeypatch):
    task = tmp_path / "task.yaml"
    task.write_text((DATA / "task_gripper.yaml").read_text().replace(
        "- robot: panda", f"- robot_config_file: {DATA / 'panda_off_tcp.yaml'}"))
    code, _, err = run_main(["validate", str(task)], capsys, monkeypatch)
    assert code == 0 and "panda_off_tcp.yaml" in err and "warning: " in err  # the robot's warning is shown
    code, _, err = run_main(["validate", "--strict", str(task)], capsys, monkeypatch)
    assert code == 2 and "tcp_offset" in err


def test_robots_lists_panda(tmp_path, capsys, monkeypatch):
    code, out, _ = run_main(["robots", "--json", str(tmp_path / "robots.json")], capsys, monkeypatch)
    assert code == 0
    assert "panda" in out and "parallel" in out
    rows = {r["name"]: r for r in json.loads((tmp_path / "robots.json").read_text())}
    assert rows["panda"]["dof"] == 7 and rows["panda"]["grippers"] == ["parallel"] and rows["panda"]["valid"]
    assert rows["dual_panda"]["arms"] == ["left", "right"] and rows["dual_panda"]["grippers"] == ["parallel", "parallel"]


def test_robots_finds_robocfg_path(tmp_path, capsys, monkeypatch):
    (tmp_path / "robots").mkdir()
    text = (ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text().replace("name: panda", "name: mypanda")
    (tmp_path / "robots" / "mypanda.yaml").write_text(text.replace("../../../docs", str(ROOT / "docs")))
    monkeypatch.setenv("ROBOCFG_PATH", str(tmp_path))
    code, out, _ = run_main(["robots"], capsys, monkeypatch)
    assert code == 0 and "mypanda" in out and "panda" in out


def test_unknown_command_arguments_exit_2_without_traceback():
    r = run_process(["inspect", "pnda"])
    assert r.returncode == 2
    assert "did you mean 'panda'?" in r.stderr and "Traceback" not in r.stderr


def test_debug_shows_traceback_for_its_own_command_line_only(capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    monkeypatch.delenv("ROBOCFG_DEBUG", raising=False)
    monkeypatch.setattr(sys, "argv", ["robocfg", "--debug", "inspect", "pnda"])
    from robocfg.errors import NotFound

    with pytest.raises(NotFound):
        main()
    # --debug is not left in the environment: child processes and the next in-process call
    # (the same command line without --debug) get the plain message, exit 2.
    import os

    assert "ROBOCFG_DEBUG" not in os.environ
    code, _, err = run_main(["inspect", "pnda"], capsys, monkeypatch)
    assert code == 2 and "did you mean 'panda'?" in err and "Traceback" not in err


# ---------------------------------------------------------------- inspect


def _pybullet_joints(urdf_path: str) -> list[tuple[str, int]]:
    """(name, type) for each PyBullet joint index, loaded headless."""
    import pybullet as p

    cid = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(urdf_path, useFixedBase=True, physicsClientId=cid)
        infos = [p.getJointInfo(body, i, physicsClientId=cid) for i in range(p.getNumJoints(body, physicsClientId=cid))]
        return [(info[1].decode(), info[2]) for info in infos]
    finally:
        p.disconnect(cid)


def test_inspect_panda_dof_indices_match_pybullet(tmp_path, capsys, monkeypatch):
    import pybullet as p

    out_json = tmp_path / "inspect.json"
    code, out, err = run_main(["inspect", "panda", "--json", str(out_json)], capsys, monkeypatch)
    assert code == 0, err
    assert "DOF" in out and "pybullet" in out and "panda_joint1" in out and "EE-link candidates" in out
    report = json.loads(out_json.read_text())
    rows = report["joints"]
    pb = _pybullet_joints(report["urdf"])
    assert len(rows) == len(pb)
    for row in rows:
        name, jtype = pb[row["pybullet_index"]]
        assert row["name"] == name
        assert row["movable"] == (jtype != p.JOINT_FIXED)
    pb_movable = [name for name, jtype in pb if jtype != p.JOINT_FIXED]
    dof_rows = sorted((r for r in rows if r["dof_index"] is not None), key=lambda r: r["dof_index"])
    assert [r["name"] for r in dof_rows] == pb_movable
    assert [r["dof_index"] for r in dof_rows] == list(range(len(pb_movable)))
    # the shipped robot's joint_indices are the DOF indices of its joint names
    arm = report["arms"][0]
    dof_of = {r["name"]: r["dof_index"] for r in rows}
    assert [dof_of[n] for n in arm["joints"]] == arm["joint_indices"]
    assert [dof_of[n] for n in arm["gripper"]["joints"]] == arm["gripper"]["gripper_indices"]
    assert "panda_hand" in report["ee_candidates"]


def test_inspect_urdf_file_directly(capsys, monkeypatch):
    import pybullet_data

    urdf = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    code, out, _ = run_main(["inspect", str(urdf)], capsys, monkeypatch)
    assert code == 0 and "panda_finger_joint2" in out and "1·panda_finger_joint1" in out


def test_inspect_broken_urdf_is_a_located_error(capsys, monkeypatch):
    code, out, err = run_main(["inspect", "tests/bad/urdf/broken.urdf"], capsys, monkeypatch)
    assert code == 2 and "Traceback" not in out + err
    assert re.match(r"^tests/bad/urdf/broken\.urdf:11: ", err)


# ---------------------------------------------------------------- schema


@pytest.mark.parametrize("kind", ["robot", "task", "report-pick-place", "report-grasp", "report-gripper",
                                  "report-trajectory", "report-follow-target"])
def test_schema_files_in_docs_are_current(kind, capsys, monkeypatch):
    """docs/schema/*.json are generated by `robocfg schema KIND -o FILE`; regenerate them with
    `robocfg schema KIND -o docs/schema/KIND.schema.json --force` after changing a model."""
    code, out, _ = run_main(["schema", kind], capsys, monkeypatch)
    assert code == 0
    committed = (ROOT / "docs" / "schema" / f"{kind}.schema.json").read_text()
    assert json.loads(out) == json.loads(committed), f"docs/schema/{kind}.schema.json is stale"
    assert out == committed


def test_schema_robot_is_valid_json_schema_and_accepts_panda(capsys, monkeypatch):
    import yaml
    from jsonschema import Draft202012Validator

    code, out, _ = run_main(["schema", "robot"], capsys, monkeypatch)
    assert code == 0
    schema = json.loads(out)
    Draft202012Validator.check_schema(schema)
    validator = Draft202012Validator(schema)
    panda = yaml.safe_load((ROOT / "robocfg" / "data" / "robots" / "panda.yaml").read_text())
    assert list(validator.iter_errors(panda)) == []
    for bad in ("robot_ee_axis_w", "robot_unknown_key_ee_lnk", "robot_tcp_zero"):  # editors flag these too
        assert list(validator.iter_errors(yaml.safe_load((BAD / f"{bad}.yaml").read_text())))


def test_schema_task_is_valid_json_schema_and_accepts_tasks(capsys, monkeypatch):
    import yaml
    from jsonschema import Draft202012Validator

    code, out, _ = run_main(["schema", "task"], capsys, monkeypatch)
    assert code == 0
    schema = json.loads(out)
    Draft202012Validator.check_schema(schema)
    validator = Draft202012Validator(schema)
    tasks = [*sorted((ROOT / "robocfg" / "data" / "tasks").glob("*.yaml")), DATA / "task_gripper.yaml", DATA / "task_pick_place.yaml"]
    for f in tasks:
        assert list(validator.iter_errors(yaml.safe_load(f.read_text()))) == [], f
    assert list(validator.iter_errors(yaml.safe_load((BAD / "task_wrong_task.yaml").read_text())))


def test_schema_output_refuses_to_overwrite_without_force(tmp_path, capsys, monkeypatch):
    target = tmp_path / "robot.schema.json"
    target.write_text("{}")
    code, _, err = run_main(["schema", "robot", "-o", str(target)], capsys, monkeypatch)
    assert code == 2 and "--force" in err and target.read_text() == "{}"
    code, _, _ = run_main(["schema", "robot", "-o", str(target), "--force"], capsys, monkeypatch)
    assert code == 0 and json.loads(target.read_text())["title"].startswith("robocfg robot")


def test_shipped_yamls_point_at_the_schema():
    for kind, folder in (("robot", "robots"), ("task", "tasks")):
        for f in sorted((ROOT / "robocfg" / "data" / folder).glob("*.yaml")):
            first = f.read_text().splitlines()[0]
            assert first.startswith("# yaml-language-server: $schema="), f
            target = (f.resolve().parent / first.split("$schema=", 1)[1]).resolve()
            assert target == (ROOT / "docs" / "schema" / f"{kind}.schema.json").resolve(), f
