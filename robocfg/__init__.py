"""robocfg: robots and tasks from validated YAML, run headless in PyBullet.

The public API (``robocfg.api``, loaded on first use so ``import robocfg`` stays fast)::

    import robocfg
    task = robocfg.load_task("pick_place", robot="panda")
    report = robocfg.run(task.with_overrides({"pick_place.lift_height": 0.15}), episodes=1)

Gymnasium environments: ``import robocfg.envs`` registers ``robocfg/PickPlace-v0`` and friends.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

__all__ = ["ConfigError", "NotFound", "RobocfgError", "RunFailed", "kinematic_model", "load_robot",
           "load_task", "make_world", "run", "solve_ik"]

if TYPE_CHECKING:
    from robocfg.api import kinematic_model, load_robot, load_task, make_world, run, solve_ik
    from robocfg.errors import ConfigError, NotFound, RobocfgError, RunFailed


def __getattr__(name: str) -> Any:
    if name in ("ConfigError", "NotFound", "RobocfgError", "RunFailed"):
        from robocfg import errors

        return getattr(errors, name)
    if name in __all__:
        from robocfg import api

        return getattr(api, name)
    raise AttributeError(f"module 'robocfg' has no attribute {name!r}")
