"""IK backends keyed by the robot YAML's ``ik_backend`` string (one dict).

A backend is a factory ``(KinematicModel) -> IKSolver`` (:mod:`robocfg.kinematics.ik.solver`:
``solve(target, seed_q, frame, time_budget, position_only, rng) -> IKResult`` and an iteration
budget ``max_total_iter``). The built-in
backends are registered when their module is imported; their heavy libraries (pink, placo) are
imported only when a solver is built.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING

from robocfg.errors import NotFound, RobocfgError

if TYPE_CHECKING:
    from robocfg.kinematics.ik.solver import IKSolver
    from robocfg.kinematics.model import KinematicModel

BackendFactory = Callable[["KinematicModel"], "IKSolver"]

_REGISTRY: dict[str, BackendFactory] = {}
_BUILTIN = {  # backend name -> the module that registers it
    "lm": "robocfg.kinematics.ik.lm",
    "pink": "robocfg.kinematics.ik.pink_qp",
    "placo": "robocfg.kinematics.ik.placo_qp",
}
_BUILTIN_MODULES = tuple(_BUILTIN.values())
_builtins_loaded = False


def register(name: str) -> Callable[[BackendFactory], BackendFactory]:
    """Decorator: register ``factory`` under ``name``; a second registration of a name is an error."""

    def deco(factory: BackendFactory) -> BackendFactory:
        if name in _REGISTRY:
            raise RobocfgError(f"IK backend {name!r} is already registered")
        _REGISTRY[name] = factory
        return factory

    return deco


def _load_builtins() -> None:
    global _builtins_loaded
    if not _builtins_loaded:
        _builtins_loaded = True
        for mod in _BUILTIN_MODULES:
            importlib.import_module(mod)


def known_backends() -> list[str]:
    """Names of every registered backend."""
    _load_builtins()
    return sorted(_REGISTRY)


def get_backend(name: str) -> BackendFactory:
    """The factory registered as ``name``; NotFound lists the known names. A built-in backend
    loads its own module only (a process that solves with ``lm`` imports neither QP module)."""
    if name in _BUILTIN and name not in _REGISTRY:
        importlib.import_module(_BUILTIN[name])
    if name not in _REGISTRY:
        _load_builtins()
    try:
        return _REGISTRY[name]
    except KeyError:
        raise NotFound("IK backend", name, sorted(_REGISTRY)) from None
