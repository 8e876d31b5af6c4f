"""robocfg.config.task: the built-in kinds other than pick-place have their models made the first
time they are used; their names stay where they were (robocfg.config.task, robocfg.config.commands)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

_PROBE = r'''
import json, sys
from robocfg.config.task import TASK_MODELS, TASK_KINDS
loaded = lambda: sorted(m for m in sys.modules if m.endswith(("_task", "multi_pick")) and m.startswith("robocfg.config"))
out = {"kinds": list(TASK_KINDS), "start": loaded(), "contains": "grasp" in TASK_MODELS and "nope" not in TASK_MODELS}
out["after_contains"] = loaded()
grasp = TASK_MODELS["grasp"]
out["grasp"] = [grasp.__module__, grasp.__name__]
out["after_grasp"] = loaded()
from robocfg.config.commands import GripperParams, Motion
from robocfg.config.task import TrajectoryTask, PickPlaceManyTask
out["names"] = [GripperParams.__module__, Motion.__module__, TrajectoryTask.__module__, PickPlaceManyTask.__module__]
import robocfg.config.task as task
out["union"] = [a.__name__ for a in task.TaskConfig.__origin__.__args__]
out["values"] = [m.__name__ for m in TASK_MODELS.values()]
try:
    task.NoSuchModel
except AttributeError as exc:
    out["missing"] = str(exc)
print(json.dumps(out))
'''


def test_other_kinds_models_are_made_on_first_use_under_their_old_names() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    run = subprocess.run([sys.executable, "-c", _PROBE], cwd=ROOT, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    out = json.loads(run.stdout.splitlines()[-1])
    order = ["gripper", "trajectory", "follow_target", "pick_place", "grasp", "pick_place_many"]
    assert out["kinds"] == order
    assert out["start"] == [] and out["contains"] and out["after_contains"] == []
    assert out["grasp"] == ["robocfg.config.grasp_task", "GraspTask"]
    assert out["after_grasp"] == ["robocfg.config.grasp_task"]
    assert out["names"] == ["robocfg.config.gripper_task", "robocfg.config.follow_target_task",
                            "robocfg.config.trajectory_task", "robocfg.config.multi_pick"]
    names = ["GripperTask", "TrajectoryTask", "FollowTargetTask", "PickPlaceTask", "GraspTask", "PickPlaceManyTask"]
    assert out["union"] == names and out["values"] == names
    assert out["missing"] == "module 'robocfg.config.task' has no attribute 'NoSuchModel'"
