"""The task registry: task kind (the YAML's ``task:`` value) → its runner class.

A task kind is one parameter model plus one runner class::

    @register_task
    class ToyRunner(TaskRunner):
        kind = "toy"                   # `task: toy` in the YAML, `robocfg run toy` on the CLI
        params = ToyParams             # the YAML's `toy:` block (a frozen pydantic model)
        report = ToyReport             # typed report: JSON, table rows, one-line summary
        ...

Registering a kind the config does not know yet declares it there too
(``robocfg.config.task.add_task_kind``), so one file adds a kind. The built-in kinds load lazily
from ``_BUILTIN_MODULES`` on the first lookup, so importing the registry loads no simulator.
"""

from __future__ import annotations

import importlib
from typing import TypeVar

from robocfg.engine.runner import TaskCommand, TaskRunner
from robocfg.errors import NotFound

_REGISTRY: dict[str, type[TaskRunner]] = {}
_BUILTIN_MODULES = (
    "robocfg.runners.gripper",
    "robocfg.runners.trajectory",
    "robocfg.runners.follow_target",
    "robocfg.runners.pick_place",
    "robocfg.runners.grasp",
    "robocfg.runners.pick_place_many",
)
_BUILTIN_KINDS = {m.rsplit(".", 1)[1]: m for m in _BUILTIN_MODULES}  # a built-in module is named after its kind
_loaded = False

R = TypeVar("R", bound=type[TaskRunner])


def register_task(cls: R) -> R:
    """Class decorator: register a runner under its ``kind``. A second class for the same kind is
    an error; a kind the config does not declare yet is declared with the runner's ``params``."""
    from robocfg.config.task import TASK_MODELS, add_task_kind, params_model

    kind = cls.kind
    if kind in _REGISTRY and _REGISTRY[kind] is not cls:
        raise ValueError(f"task kind {kind!r} is already registered by {_REGISTRY[kind].__qualname__}")
    if kind in TASK_MODELS:
        if params_model(kind) is not cls.params:
            raise ValueError(f"task kind {kind!r}: the runner's params {cls.params.__name__} is not the config's "
                             f"{params_model(kind).__name__}")
    else:
        add_task_kind(kind, cls.params, cls.summary)
    _REGISTRY[kind] = cls
    return cls


def unregister_task(kind: str) -> None:
    """Remove a kind added at run time (tests that register a toy kind clean up with it); the
    built-in kinds stay."""
    from robocfg.config.task import remove_task_kind

    _load_builtins()
    if _REGISTRY.get(kind) is not None and _REGISTRY[kind].__module__ in _BUILTIN_MODULES:
        raise ValueError(f"task kind {kind!r} is built in")
    _REGISTRY.pop(kind, None)
    remove_task_kind(kind)


def _load_builtins() -> None:
    global _loaded
    if not _loaded:
        _loaded = True
        for module in _BUILTIN_MODULES:
            importlib.import_module(module)


def runner_for(kind: str) -> type[TaskRunner]:
    """The runner class of a task kind (``NotFound`` with a did-you-mean otherwise). A built-in
    kind loads only its own module (a worker or a ``robocfg run`` of one kind imports one runner,
    not six: ≈ 0.1–0.2 s of a fresh process); any other name loads them all first."""
    module = _BUILTIN_KINDS.get(kind)
    if module is not None and kind not in _REGISTRY:
        importlib.import_module(module)
    if kind not in _REGISTRY:
        _load_builtins()
    if kind not in _REGISTRY:
        raise NotFound("task kind", kind, list(_REGISTRY))
    return _REGISTRY[kind]


def command_for(kind: str) -> type[TaskCommand]:
    """What ``robocfg run KIND`` shows and parses before running (its help, own options, whether
    it has episodes): a built-in kind not loaded yet gives its :func:`builtin_command`, so
    ``--help`` loads no episode code; any other kind gives its runner."""
    if kind not in _REGISTRY:
        command = builtin_command(kind)
        if command is not None:
            return command
    return runner_for(kind)


def builtin_command(kind: str) -> type[TaskCommand] | None:
    """The command face of a built-in kind: class ``<Kind>Command`` of the light module
    ``robocfg.runners.<kind>_command``, which the kind's runner subclasses (a test checks every
    built-in kind); None for any other kind."""
    module = _BUILTIN_KINDS.get(kind)
    if module is None:
        return None
    name = "".join(w.capitalize() for w in kind.split("_")) + "Command"
    command = getattr(importlib.import_module(f"{module}_command"), name)
    if not (isinstance(command, type) and issubclass(command, TaskCommand) and command.kind == kind):
        raise TypeError(f"{module}_command.{name} is not the TaskCommand of kind {kind!r}")
    return command


def registered() -> dict[str, type[TaskRunner]]:
    """Every registered kind → runner: the built-ins in ``_BUILTIN_MODULES`` order, then the
    others in registration order."""
    _load_builtins()
    builtin = {k: _REGISTRY[k] for k in _BUILTIN_KINDS if k in _REGISTRY}
    return builtin | {k: v for k, v in _REGISTRY.items() if k not in builtin}


def builtin_kind(name: str) -> str | None:
    """The built-in kind whose ``robocfg run`` sub-command is ``name`` (``pick-place`` →
    ``pick_place``), loading nothing; None for any other name."""
    kind = name.replace("-", "_")
    return kind if kind in _BUILTIN_KINDS and command_name(kind) == name else None


def command_name(kind: str) -> str:
    """The ``robocfg run`` sub-command of a kind: ``pick_place`` → ``pick-place``."""
    return kind.replace("_", "-")
