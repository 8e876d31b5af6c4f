"""Reach is checked against the robot before simulating: validate warns, and run exits 1 naming
the phase (report written) when the task's object or place spot is out of the arm's reach."""

import json

import yaml
from _cli import run_main

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.motion.reach import pick_place_reach


def _default_task_on(tmp_path, robot: str):
    data = yaml.safe_load(catalog.find("tasks", "pick_place").read_text())
    data["robots"][0]["robot"] = robot
    data["pick_place"]["placement"] = "world"  # the desk spots as world coordinates, whatever the robot
    path = tmp_path / f"pick_place_{robot}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def test_desk_spots_are_out_of_a_kr210s_reach(tmp_path):
    problems = pick_place_reach(load_task(_default_task_on(tmp_path, "kuka_kr210")))
    nominal = {(p.phase, p.loc[-1]) for p in problems if p.nominal}
    assert nominal == {("pre_grasp", "position"), ("transport", "place_position")}
    assert all(p.residual > 0.1 for p in problems)


def test_shipped_pick_place_tasks_are_in_reach():
    """Every built-in pick-place task (bins, fixtures, pedestals, tables included) is in reach."""
    tasks = [load_task(path) for path in catalog.available("tasks").values()]
    pick_place = [t for t in tasks if t.config.task == "pick_place"]
    assert len(pick_place) >= 4
    for task in pick_place:
        assert pick_place_reach(task) == [], task.path.name


def test_validate_warns_and_run_fails_before_simulating(tmp_path, capsys, monkeypatch):
    path = _default_task_on(tmp_path, "kuka_kr210")
    code, _, err = run_main(["validate", str(path)], capsys, monkeypatch)
    assert code == 0
    assert "pick_place.object.position: warning: pre_grasp: the pose above the object is unreachable, out of the arm's reach" in err
    assert "give them relative to the arm with 'placement: reach'" in err  # what to do about it
    out_json = tmp_path / "r.json"
    code, out, err = run_main(["run", "pick-place", str(path), "-n", "2", "-q", "--json", str(out_json)], capsys, monkeypatch)
    assert code == 1
    assert "pre_grasp: the pose above the object is unreachable, out of the arm's reach" in out
    warned = [line for line in err.splitlines() if "warning:" in line]
    assert warned and all(line.count("warning:") == 1 for line in warned), err  # said once per line
    report = json.loads(out_json.read_text())
    assert [e["failed_phase"] for e in report["episodes"]] == ["pre_grasp", "pre_grasp"]
    assert all(e["steps"] == 0 for e in report["episodes"])  # nothing was simulated


def test_support_is_the_fixture_below_the_spot():
    """The cell task's panel lies on a 1.91 m fixture: the reach check asks for poses above it, not
    above the ground (which no arm on the 2.51 m pedestal could reach)."""
    from robocfg.motion.reach import support_height

    task = load_task(catalog.find("tasks", "pick_place_cell"))
    obj = task.config.pick_place.object
    assert abs(support_height(task.config.scene, obj.position[0], obj.position[1]) - 1.91) < 1e-6
    assert support_height(task.config.scene, 3.0, 3.0) == 0.0
    assert pick_place_reach(task) == []
