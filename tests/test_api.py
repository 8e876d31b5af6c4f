"""The public Python API on real robots, tasks and worlds, and the runnable docs examples."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import robocfg

DOC = Path(__file__).resolve().parent.parent / "docs" / "python-api.md"


def test_import_is_lazy():
    code = "import sys, robocfg; print('pybullet' in sys.modules, 'pinocchio' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_load_task_with_robot_and_overrides():
    task = robocfg.load_task("pick_place", robot="xarm6", overrides={"pick_place.lift_height": 0.2})
    assert task.robots[0].config.name == "xarm6"
    assert task.config.pick_place.lift_height == 0.2


def test_unknown_names_raise_not_found_with_suggestion():
    with pytest.raises(robocfg.NotFound, match="did you mean 'panda'"):
        robocfg.load_robot("pnda")


def test_run_returns_the_typed_report():
    report = robocfg.run(robocfg.load_task("pick_place"), episodes=1, seed=3)
    assert type(report).__name__ == "PickPlaceReport"
    assert report.seed == 3 and len(report.episodes) == 1 and report.summary.successes == 1


def test_world_steps_and_ik_matches_fk():
    task = robocfg.load_task("gripper")
    with robocfg.make_world(task) as world:
        world.step(24)
        assert world.t == pytest.approx(24 * world.dt)
    model = robocfg.kinematic_model("panda")
    target = model.fk(model.home)
    target[:3, 3] += [0.0, 0.05, -0.1]
    res = robocfg.solve_ik(model, target)
    assert res.converged
    np.testing.assert_allclose(model.fk(res.q)[:3, 3], target[:3, 3], atol=1e-4)


def _snippets() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)


def test_docs_have_examples():
    assert len(_snippets()) >= 4


@pytest.mark.parametrize("k", range(len(_snippets())))
def test_docs_example_runs(k, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    exec(compile(_snippets()[k], f"{DOC.name} example {k}", "exec"), {})
