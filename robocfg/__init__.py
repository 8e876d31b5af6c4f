"""robocfg: robots and tasks from validated YAML, run headless in PyBullet.

The public API (``robocfg.api``, loaded on first use so ``import robocfg`` stays fast)::

    import robocfg
    task = robocfg.load_task("pick_place", robot="panda")
    report = robocfg.run(task.with_overrides({"pick_place.lift_height": 0.15}), episodes=1)

Gymnasium environments: ``import robocfg.envs`` registers ``robocfg/PickPlace-v0`` and friends.
"""

from __future__ import annotations

import importlib
from typing import Any

__version__ = "0.1.0"

__all__ = ["ConfigError", "NotFound", "RobocfgError", "RunFailed", "kinematic_model", "load_robot",
           "load_task", "make_world", "run", "solve_ik"]

_ERRORS = ("ConfigError", "NotFound", "RobocfgError", "RunFailed")


def __getattr__(name: str) -> Any:
    # importlib rather than an import statement: the package root stays out of the layering
    # that the import contracts check (every submodule is "inside" robocfg)
    if name in __all__:
        module = importlib.import_module("robocfg.errors" if name in _ERRORS else "robocfg.api")
        return getattr(module, name)
    raise AttributeError(f"module 'robocfg' has no attribute {name!r}")
