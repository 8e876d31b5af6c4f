"""One consistent CLI: readable help, `tasks` and `robots` listings, errors blamed on what was
typed, and a source checkout whose ./robots is the user's folder (not the built-ins)."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pybullet_data
import typer.main
from _cli import run_main

from robocfg.cli.app import app
from robocfg.cli.help_style import first_sentence
from robocfg.config import catalog

ROOT = Path(__file__).resolve().parent.parent
PANDA_URDF = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"


def _commands(group, prefix=()):
    ctx = group.make_context(group.name, ["--help"], resilient_parsing=True)  # the run group loads lazily
    for name in group.list_commands(ctx):
        cmd = group.get_command(ctx, name)
        yield (*prefix, name), cmd
        if hasattr(cmd, "commands"):
            yield from _commands(cmd, (*prefix, name))


def test_every_help_has_readable_placeholders_and_whole_summaries(capsys, monkeypatch):
    root = typer.main.get_command(app)
    paths = [p for p, _ in _commands(root)]
    assert ("tasks",) in paths and ("run", "pick-place") in paths and ("bench", "ik") in paths
    for path in [(), *paths]:
        code, out, _ = run_main([*path, "--help"], capsys, monkeypatch)
        assert code == 0, path
        # no Python type names as placeholders, no summary cut short
        assert not re.search(r"<[a-z][\w\[\], ]*>", out), (path, out)
        assert "..." not in out.replace("[ARGS]...", "").replace("`run ... --dataset`", "").replace("]...", ""), (path, out)
    code, out, _ = run_main(["ik", "--help"], capsys, monkeypatch)
    assert "--position X Y Z" in out and "--euler-deg R P Y" in out and "--quat-xyzw X Y Z W" in out
    assert "--budget-ms X" in out and "ROBOT  " in out
    code, out, _ = run_main(["validate", "--help"], capsys, monkeypatch)
    assert "[PATHS]..." in out and "--json PATH" in out


def test_summary_is_the_first_sentence_whole():
    assert first_sentence("Draft a robot YAML from a URDF. Then more.") == "Draft a robot YAML from a URDF."
    assert first_sentence("Inspect datasets written by `run ... --dataset`.") == \
        "Inspect datasets written by `run ... --dataset`."
    assert first_sentence("Spans\n  two lines, e.g. this. Rest.") == "Spans two lines, e.g. this."


def test_shell_completion_is_offered(capsys, monkeypatch):
    code, out, _ = run_main(["--help"], capsys, monkeypatch)
    assert code == 0 and "--install-completion" in out and "--show-completion" in out


def test_tasks_lists_every_task_with_kind_robot_and_command(capsys, monkeypatch, tmp_path):
    out_json = tmp_path / "tasks.json"
    code, out, _ = run_main(["tasks", "--json", str(out_json)], capsys, monkeypatch)
    assert code == 0
    entries = {e["name"]: e for e in json.loads(out_json.read_text())}
    assert set(entries) == set(catalog.available("tasks"))
    pp = entries["pick_place"]
    assert (pp["kind"], pp["robots"], pp["valid"]) == ("pick_place", ["panda"], True)
    assert pp["command"] == "robocfg run pick-place pick_place" and pp["description"]
    assert entries["pick_place_kuka_kr210"]["robots"] == ["kuka_kr210"]
    assert "pick_place_kuka_kr210" in out


def test_tasks_lists_an_invalid_user_task_as_invalid(capsys, monkeypatch, tmp_path):
    (tmp_path / "tasks").mkdir()
    (tmp_path / "tasks" / "mine.yaml").write_text("schema_version: 1\ntask: pick_place\nrobots: []\n")
    code, _, _ = run_main(["tasks", "--json", str(tmp_path / "t.json")], capsys, monkeypatch, tmp_path)
    assert code == 0
    [mine] = [e for e in json.loads((tmp_path / "t.json").read_text()) if e["name"] == "mine"]
    assert mine["valid"] is False and mine["problems"] >= 1 and mine["errors"]


def test_robots_json_has_lists_and_descriptions(capsys, monkeypatch, tmp_path):
    code, _, _ = run_main(["robots", "--json", str(tmp_path / "r.json")], capsys, monkeypatch)
    assert code == 0
    entries = {e["name"]: e for e in json.loads((tmp_path / "r.json").read_text())}
    dual = entries["dual_panda"]
    assert dual["arms"] == ["left", "right"] and dual["grippers"] == ["parallel", "parallel"]
    assert dual["dof"] == 14 and dual["valid"] and dual["description"]


def test_unknown_robot_option_is_blamed_on_the_option(capsys, monkeypatch):
    code, out, err = run_main(["run", "pick-place", "--robot", "pnda"], capsys, monkeypatch)
    assert code == 2 and "Traceback" not in out + err
    assert err.startswith("--robot pnda: unknown robot; did you mean 'panda'?")
    assert "pick_place.yaml" not in err


def test_bench_ik_takes_n_like_run(capsys, monkeypatch):
    code, out, _ = run_main(["bench", "ik", "--help"], capsys, monkeypatch)
    assert code == 0 and "-n, --targets N" in out


def test_checkout_robots_folder_is_the_users_not_the_builtins():
    for folder in ("robots", "tasks"):
        d = ROOT / folder
        assert d.is_dir() and not d.is_symlink(), folder
        assert not list(d.glob("*.yaml")), f"built-in YAMLs belong in robocfg/data/{folder}"
    # built-ins are the package's own data (the checkout's with an editable install, site-packages'
    # with a plain `pip install .` as CI does), never the checkout's top-level user folders
    import robocfg

    assert Path(robocfg.__file__).resolve().parent / "data" == catalog.BUILTIN_DIR
    assert catalog.BUILTIN_DIR.resolve() not in {(ROOT / "robots").resolve(), (ROOT / "tasks").resolve()}


def test_new_robot_in_a_checkout_writes_to_the_users_folder(capsys, monkeypatch, tmp_path):
    builtins_before = sorted((catalog.BUILTIN_DIR / "robots").iterdir())
    code, _, err = run_main(["new-robot", str(PANDA_URDF), "-o", str(catalog.BUILTIN_DIR / "robots" / "x.yaml")],
                            capsys, monkeypatch, tmp_path)
    assert code == 2 and "--output" in err and "built-in" in err
    assert sorted((catalog.BUILTIN_DIR / "robots").iterdir()) == builtins_before
    code, out, _ = run_main(["new-robot", str(PANDA_URDF), "-o", "robots/my_panda.yaml"], capsys, monkeypatch, tmp_path)
    assert code == 0, out
    assert (tmp_path / "robots" / "my_panda.yaml").is_file()
    monkeypatch.chdir(tmp_path)
    assert catalog.find("robots", "my_panda").resolve() == (tmp_path / "robots" / "my_panda.yaml").resolve()


def test_set_changes_a_task_field_validated_like_the_file(capsys, monkeypatch, tmp_path):
    task = str(ROOT / "robocfg" / "data" / "tasks" / "pick_place.yaml")
    code, _, err = run_main(["validate", task, "--set", "pick_place.lift_height=0.3"], capsys, monkeypatch)
    assert code == 0, err
    code, _, err = run_main(["validate", task, "--set", "pick_place.lift_hight=0.3", "--set", "sim.seed=-1",
                             "--set", "pick_place.place_position=[0.5, 0.3]", "--json", str(tmp_path / "v.json")],
                            capsys, monkeypatch)
    assert code == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert "--set pick_place.lift_hight: unknown key 'lift_hight'; did you mean 'lift_height'?" in lines
    assert any(line.startswith("--set sim.seed: ") for line in lines)
    assert any(line.startswith("--set pick_place.place_position: ") for line in lines)
    assert not any("pick_place.yaml:" in line for line in lines)  # the file is fine; the options are not
    [record] = json.loads((tmp_path / "v.json").read_text())["files"]
    assert {p["path"] for p in record["problems"]} == {"pick_place.lift_hight", "sim.seed", "pick_place.place_position"}


def test_set_without_equals_or_with_bad_yaml_is_a_usage_error(capsys, monkeypatch):
    for bad, expected in (("lift_height", "--set lift_height: expected KEY=VALUE"),
                          ("pick_place.lift_height=[1,", "--set pick_place.lift_height: value '[1,' is not a YAML value")):
        code, _, err = run_main(["validate", "pick_place.yaml", "--set", bad], capsys, monkeypatch)
        assert code == 2 and err.startswith(expected), err


def test_view_set_needs_a_task(capsys, monkeypatch):
    code, _, err = run_main(["view", "panda", "--png", "x.png", "--set", "name=other"], capsys, monkeypatch)
    assert code == 2 and err.startswith("--set: 'panda' is a robot"), err


def test_inspect_takes_the_urdf_uris_a_robot_yaml_takes(capsys, monkeypatch, tmp_path):
    code, _, _ = run_main(["inspect", "pybullet_data://franka_panda/panda.urdf", "--json", str(tmp_path / "i.json")],
                          capsys, monkeypatch)
    assert code == 0
    info = json.loads((tmp_path / "i.json").read_text())
    assert Path(info["urdf"]) == PANDA_URDF.resolve()
    assert [j["name"] for j in info["joints"] if j["dof_index"] is not None][:2] == ["panda_joint1", "panda_joint2"]
    code, _, err = run_main(["inspect", "pybullet_data://no/such.urdf"], capsys, monkeypatch)
    assert code == 2 and "cannot resolve 'pybullet_data://no/such.urdf'" in err


def test_validate_takes_names_from_the_search_path(capsys, monkeypatch, tmp_path):
    code, _, err = run_main(["validate", "pick_place", "panda", "--json", str(tmp_path / "v.json")], capsys, monkeypatch)
    assert code == 0, err
    files = [Path(f["file"]).resolve() for f in json.loads((tmp_path / "v.json").read_text())["files"]]
    assert files == [catalog.find("tasks", "pick_place").resolve(), catalog.find("robots", "panda").resolve()]
    code, _, err = run_main(["validate", "no_such_thing"], capsys, monkeypatch)
    assert code == 2 and "no_such_thing: file not found" in err


def test_every_run_kind_takes_set_and_blames_it(capsys, monkeypatch):
    from robocfg.engine.registry import command_name, registered

    for kind in registered():
        code, out, _ = run_main(["run", command_name(kind), "--help"], capsys, monkeypatch)
        assert code == 0 and "--set KEY=VALUE" in out and "-n, --episodes N" in out, kind
    code, out, err = run_main(["run", "pick-place", "--set", "pick_place.lift_hight=0.2", "-q"], capsys, monkeypatch)
    assert code == 2 and "Traceback" not in out + err
    assert err.startswith("--set pick_place.lift_hight: unknown key 'lift_hight'; did you mean 'lift_height'?")


def test_run_set_changes_the_run(capsys, monkeypatch, tmp_path):
    report = tmp_path / "r.json"
    code, _, err = run_main(["run", "trajectory", "--set", "trajectory.limits.velocity_scale=0.2", "--no-sim", "-q",
                             "--json", str(report)], capsys, monkeypatch)
    assert code == 0, err
    slow = json.loads(report.read_text())["duration"]
    code, _, err = run_main(["run", "trajectory", "--no-sim", "-q", "--json", str(report)], capsys, monkeypatch)
    assert code == 0, err
    assert slow > 1.5 * json.loads(report.read_text())["duration"]


def _complete(words: str) -> list[str]:
    """What bash completion offers after ``words`` (the protocol the installed script speaks)."""
    env = {**os.environ, "_ROBOCFG_COMPLETE": "complete_bash", "COMP_WORDS": words,
           "COMP_CWORD": str(len(words.split()) - 1)}
    script = "import sys; sys.argv[0] = 'robocfg'; from robocfg.cli.app import main; main()"
    proc = subprocess.run([sys.executable, "-c", script], env=env, cwd=ROOT, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.split()


def test_shell_completion_offers_task_and_robot_names():
    tasks = _complete("robocfg run pick-place pick")
    assert "pick_place" in tasks and "pick_place_obstacle" in tasks
    assert all(catalog.find("tasks", t) for t in tasks)
    assert "gripper" not in _complete("robocfg run pick-place g")  # a task of another kind
    robots = _complete("robocfg run gripper --robot ur")
    assert "ur5e_robotiq_2f85" in robots and all(r.startswith("ur") for r in robots)


def test_bad_option_values_are_named_by_their_option(capsys, monkeypatch):
    cases = ((["ik", "panda", "--position", "0.5", "0", "0.3", "--quat-xyzw", "0", "0", "0", "0"],
              "--quat-xyzw: quat_xyzw must be a unit quaternion"),
             (["ik", "panda", "--position", "0.5", "0", "0.3", "--euler-deg", "1", "2", "3", "--quat-xyzw", "0", "0", "0", "1"],
              "--euler-deg/--quat-xyzw: give one orientation"),
             (["ik", "panda", "--position", "0.5", "0", "0.3", "--seed-q", "abc"], "--seed-q: expected numbers"),
             (["bench", "ik", "--budget-clock", "sundial"], "--budget-clock: expected wall or cpu"))
    for args, start in cases:
        code, out, err = run_main(args, capsys, monkeypatch)
        assert code == 2 and err.startswith(start) and "Traceback" not in out + err, (args, err)


def test_every_summary_fits_one_line_of_a_plain_terminal(capsys, monkeypatch):
    root = typer.main.get_command(app)
    groups = [(), *[p for p, cmd in _commands(root) if hasattr(cmd, "commands")]]
    for path in groups:
        code, out, _ = run_main([*path, "--help"], capsys, monkeypatch)
        listing = out.split("Commands:\n", 1)[1].splitlines()
        wrapped = [line for line in listing if line.startswith(" " * 5)]  # a continuation line
        assert code == 0 and not wrapped, (path, out)
