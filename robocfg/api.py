"""The public Python API: load robots and tasks, derive modified copies, run tasks, build a
world and step it, solve IK. ``import robocfg`` exposes these names lazily (no PyBullet or
pinocchio import until one is used).

Frames and units are those of the YAML files: world frame z up, metres, radians; poses are 4x4
homogeneous matrices. Errors are ``robocfg.errors`` exceptions: ``ConfigError`` (invalid input,
with ``FILE:LINE:COL`` problems), ``NotFound`` (unknown name, lists the known ones),
``RunFailed`` (a run that could not succeed; ``.report`` holds the report so far).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robocfg.config import catalog

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.checks.task import CheckedTask
    from robocfg.engine import RunOptions
    from robocfg.kinematics.ik.result import IKResult
    from robocfg.kinematics.model import KinematicModel
    from robocfg.sim.world import World


def load_robot(name_or_path: str | Path, strict: bool = False) -> CheckedRobot:
    """A robot YAML by name on the search path (``"panda"``) or by file path, validated and
    cross-checked against its URDF. ``strict`` turns warnings into errors."""
    from robocfg.checks.robot import load_robot as _load

    return _load(catalog.find("robots", str(name_or_path)), strict=strict)


def load_task(name_or_path: str | Path, robot: str | None = None,
              overrides: Mapping[str, Any] | None = None, strict: bool = False) -> CheckedTask:
    """A task YAML by name (``"pick_place"``) or path, validated with the robots it names.

    ``robot`` replaces the first robot by name; ``overrides`` sets dotted keys before validation
    (``{"pick_place.lift_height": 0.2}``). ``task.with_overrides(...)`` derives copies later."""
    from robocfg.checks.task import load_task as _load

    return _load(catalog.find("tasks", str(name_or_path)), strict=strict, robot_override=robot,
                 overrides=overrides)


def run(task: CheckedTask, options: RunOptions | None = None, **kwargs: Any) -> Any:
    """Run a task of any kind headless and return its typed report (the same object the CLI
    writes as JSON). ``options`` is a :class:`robocfg.engine.RunOptions`; or give its fields as
    keywords (``episodes=``, ``seed=``, ``arm=``...) and the kind's own options too
    (``with_obstacle=`` for follow_target, ``no_sim=`` for trajectory). A failed run raises
    ``RunFailed`` whose ``.report`` holds the report."""
    import dataclasses

    from robocfg.engine import RunOptions as Options
    from robocfg.engine import runner_for

    runner_type = runner_for(task.config.task)
    own = {f.name for f in dataclasses.fields(Options)}
    base = options or Options()
    extras = None
    kind_kw = {k: v for k, v in kwargs.items() if k not in own}
    if runner_type.Options is not None:
        extras = dataclasses.replace(base.extras or runner_type.Options(), **kind_kw)
    elif kind_kw:
        raise TypeError(f"run of a {task.config.task!r} task has no option(s) {sorted(kind_kw)}")
    opts = dataclasses.replace(base, extras=extras, **{k: v for k, v in kwargs.items() if k in own})
    runner = runner_type(task, opts)
    runner.check()
    return runner.run().report


def make_world(task: CheckedTask, gui: bool = False) -> World:
    """A PyBullet world (``DIRECT`` unless ``gui``) built from the task's scene and robots. Use it
    as a context manager; ``world.step(n)`` advances ``n`` physics steps of ``world.dt`` s."""
    from robocfg.sim.world import World

    return World(task, gui=gui)


def kinematic_model(robot: CheckedRobot | str, arm: str | None = None, base_pose: Any = None) -> KinematicModel:
    """The pinocchio model of one arm (default: the first), frames ``"tcp"`` and ``"ee"``;
    ``base_pose`` is the 4x4 world pose of the robot's base (default: identity)."""
    from robocfg.kinematics.model import KinematicModel

    checked = load_robot(robot) if isinstance(robot, str) else robot
    return KinematicModel.from_robot(checked, arm=arm, base_pose=base_pose)


def solve_ik(model: KinematicModel, target: Any, seed_q: Any = None, frame: str = "tcp",
             backend: str | None = None) -> IKResult:
    """Joint values (rad or m) putting ``frame`` at ``target`` (4x4, world). Never raises for an
    unreachable target: check ``result.converged`` and the residuals."""
    return model.ik(target, seed_q=seed_q, frame=frame, backend=backend)
