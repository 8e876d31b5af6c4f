"""Load a task YAML, validate it, load the robots it names, and check the command block."""

from __future__ import annotations

import copy
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from pydantic import TypeAdapter, ValidationError

from robocfg.checks.grip_force import check_grip_force
from robocfg.checks.object_fit import check_object_fit
from robocfg.checks.robot import CheckedRobot, load_robot
from robocfg.checks.scene import check_scene
from robocfg.checks.task_params import check_task_params
from robocfg.config import catalog
from robocfg.config.load import YamlDocument, load_yaml
from robocfg.config.overrides import (
    ROBOT_OVERRIDE_SOURCE,
    apply_overrides,
    blame_overrides,
    parse_key,
)
from robocfg.config.scene import Body
from robocfg.config.task import TASK_MODELS, PickPlaceTask, TaskBase, task_union
from robocfg.config.validation import validate_document
from robocfg.errors import ConfigError, NotFound, Problem
from robocfg.suggest import did_you_mean

if TYPE_CHECKING:  # made when a task of their kind is validated (robocfg.config.task)
    from robocfg.config.task import TaskConfig

_TASK_ADAPTER: tuple[tuple[str, ...], TypeAdapter[TaskBase]] | None = None


def task_adapter() -> TypeAdapter[TaskBase]:
    """The validator of task YAMLs, rebuilt when a task kind has been declared since."""
    global _TASK_ADAPTER
    kinds = tuple(TASK_MODELS)
    if _TASK_ADAPTER is None or _TASK_ADAPTER[0] != kinds:
        _TASK_ADAPTER = (kinds, TypeAdapter(task_union()))
    return _TASK_ADAPTER[1]


def _validate_task(doc: YamlDocument) -> TaskConfig:
    """``doc`` validated against the model of the kind its ``task:`` names (the member the union
    would pick, so the same result) without building the whole union's validator (every kind's
    models: ≈ 0.08 s of a process's start); an invalid document is validated by the union, so its
    problems read as they always did."""
    kind = doc.data.get("task") if isinstance(doc.data, dict) else None
    model = TASK_MODELS.get(kind) if isinstance(kind, str) else None
    if model is not None:
        try:
            return cast("TaskConfig", model.model_validate(doc.data))  # every kind's model is a TaskConfig member
        except ValidationError:
            pass  # reported by the union below
    return validate_document(doc, task_adapter())


@dataclass
class CheckedTask:
    config: TaskConfig
    doc: YamlDocument
    robots: list[CheckedRobot]
    warnings: list[Problem] = field(default_factory=list)
    written_robot: Path | None = None  # the first robot's YAML as the file names it (before --robot / --set)

    @property
    def path(self) -> Path:
        return self.doc.path

    def with_overrides(self, overrides: Mapping[str, Any], strict: bool = False) -> CheckedTask:
        """A re-validated copy with dotted keys set (``{"pick_place.lift_height": 0.2}``); the
        same checks as loading the file, problems inside an override named after its key."""
        return check_task_document(self.doc, strict=strict, overrides=overrides)


def load_task(path: str | Path, strict: bool = False, robot_override: str | None = None,
              overrides: Mapping[str, Any] | None = None) -> CheckedTask:
    """Load and check a task YAML. ``robot_override`` replaces the first robot (``--robot NAME``);
    ``overrides`` sets dotted keys before validation (see ``robocfg.config.overrides``)."""
    return check_task_document(load_yaml(path), strict, robot_override, overrides)


def check_task_document(doc: YamlDocument, strict: bool = False, robot_override: str | None = None,
                        overrides: Mapping[str, Any] | None = None) -> CheckedTask:
    """Validate a loaded task document and load and check the robots it names.

    The ``variants`` entry of the robot that runs the task is applied first (user ``overrides``
    win over it); a problem inside a variant's value is reported at its line in the file.
    Checking the file as written also checks every other robot's variant."""
    name, variant = _variant(doc, robot_override, overrides)
    changes = {**variant, **(overrides or {})}
    original = doc
    if changes:
        doc = apply_overrides(doc, changes)
    elif robot_override is not None:
        doc = YamlDocument(doc.path, copy.deepcopy(doc.data), doc.marks)
    try:
        checked = _check_document(doc, strict, robot_override)
    except ConfigError as exc:
        exc = _blame_variant(exc, original, name, [k for k in variant if k not in (overrides or {})])
        raise blame_overrides(exc, overrides or {}) from None
    if robot_override is None and not overrides:
        _check_other_variants(original, strict, checked.config.robots[0].robot)
    checked.written_robot = _written_robot(original)
    return checked


def _written_robot(doc: YamlDocument) -> Path | None:
    """The robot YAML the file names for its first robot (``placement: auto`` scales the spots
    from its reach); None when it cannot be found (the checks report that)."""
    robots = doc.data.get("robots") if isinstance(doc.data, dict) else None
    first = robots[0] if isinstance(robots, list) and robots and isinstance(robots[0], dict) else {}
    try:
        if isinstance(first.get("robot"), str):
            return catalog.find("robots", first["robot"])
        if isinstance(first.get("robot_config_file"), str):
            path = (doc.path.parent / first["robot_config_file"]).resolve()
            return path if path.is_file() else None
    except NotFound:
        return None
    return None


def _variant(doc: YamlDocument, robot_override: str | None,
             overrides: Mapping[str, Any] | None) -> tuple[str | None, dict[str, Any]]:
    """The robot that will run and its raw ``variants`` entry (before validation; a malformed
    ``variants`` block is left for validation to report)."""
    data = doc.data if isinstance(doc.data, dict) else {}
    name = robot_override or (overrides or {}).get("robots.0.robot")
    robots = data.get("robots")
    if name is None and isinstance(robots, list) and robots and isinstance(robots[0], dict):
        name = robots[0].get("robot")
    variants = data.get("variants")
    entry = variants.get(name) if isinstance(variants, dict) and isinstance(name, str) else None
    return (name if isinstance(name, str) else None), (dict(entry) if isinstance(entry, dict) else {})


def _blame_variant(exc: ConfigError, doc: YamlDocument, name: str | None, keys: list[str]) -> ConfigError:
    """Problems inside a variant's value, located at that value in the file
    (``variants.NAME.pick_place.place_position[0]``)."""
    locs = []
    for k in keys:
        try:
            locs.append((parse_key(k), k))
        except ConfigError:
            continue
    out = []
    for prob in exc.problems:
        try:
            loc = parse_key(prob.path) if prob.path else ()
        except ConfigError:
            loc = ()
        hit = next(((kl, k) for kl, k in locs if loc[: len(kl)] == kl), None)
        out.append(doc.problem(("variants", name, hit[1], *loc[len(hit[0]):]), prob.message, prob.severity)
                   if hit and name is not None else prob)
    return ConfigError(out)


def _check_other_variants(doc: YamlDocument, strict: bool, running: str | None) -> None:
    """Each ``variants`` entry checked with its robot: a robot name not on the search path, or a
    variant that makes the task invalid, is an error at that entry."""
    problems: list[Problem] = []
    known = catalog.available("robots")
    for name in doc.data.get("variants") or {}:
        if name == running:
            continue
        loc = ("variants", name)
        if name not in known:
            problems.append(doc.problem(loc, f"no robot {name!r} on the search path{did_you_mean(name, known)}"))
            continue
        try:
            check_task_document(doc, strict, robot_override=name)
        except ConfigError as exc:
            problems.append(doc.problem(loc, f"with robot {name!r} the task is invalid ({len(exc.problems)} problem(s) below)"))
            problems.extend(exc.problems)
    if problems:
        raise ConfigError(problems)


def _check_document(doc: YamlDocument, strict: bool, robot_override: str | None) -> CheckedTask:
    if robot_override is not None and isinstance(doc.data.get("robots"), list) and doc.data["robots"]:
        first = dict(doc.data["robots"][0]) if isinstance(doc.data["robots"][0], dict) else {}
        first.pop("robot_config_file", None)
        first["robot"] = robot_override
        doc.data["robots"][0] = first
    config = _validate_task(doc)
    problems: list[Problem] = []
    robots: list[CheckedRobot] = []
    for i, mount in enumerate(config.robots):
        loc = ("robots", i, "robot" if mount.robot else "robot_config_file")
        try:
            if mount.robot is not None:
                rpath = catalog.find("robots", mount.robot)
            else:  # the mount model holds exactly one of the two
                rpath = (doc.path.parent / str(mount.robot_config_file)).resolve()
                if not rpath.is_file():
                    problems.append(doc.problem(loc, f"robot file not found: {rpath}"))
                    continue
            robots.append(load_robot(rpath, strict=strict))
        except NotFound as exc:
            if i == 0 and robot_override is not None:  # the name the caller gave, not the file, is wrong
                problems.append(Problem(ROBOT_OVERRIDE_SOURCE, None, None, robot_override,
                                        f"unknown robot{did_you_mean(exc.name, exc.known)}; known: {', '.join(sorted(exc.known))}"))
            else:
                problems.append(doc.problem(loc, str(exc)))
        except ConfigError as exc:
            what = f"robot {mount.robot or mount.robot_config_file!r} is invalid ({len(exc.problems)} problem(s) below)"
            if i == 0 and robot_override is not None:
                problems.append(Problem(ROBOT_OVERRIDE_SOURCE, None, None, robot_override, what))
            else:
                problems.append(doc.problem(loc, what))
            problems.extend(exc.problems)
    warnings: list[Problem] = []
    obj = config.pick_place.object if isinstance(config, PickPlaceTask) else None
    extra: list[tuple[tuple, Body]] = [] if obj is None else [(("pick_place", "object"), obj)]
    if config.task == "pick_place_many":
        extra = [(("pick_place_many", "objects", k), o) for k, o in enumerate(config.pick_place_many.objects)]
    problems += check_scene(doc, config.scene, extra)
    if not problems:
        problems += check_task_params(doc, config, robots[0])
    if not problems and config.task == "pick_place_many":
        from robocfg.checks.clutter import check_many

        problems += check_many(doc, config.scene, config.pick_place_many)
    if not problems and isinstance(config, PickPlaceTask):
        _check_pick_place(doc, config, robots[0], problems, warnings)
    if problems or (strict and warnings):
        raise ConfigError(problems + (warnings if strict else []))
    robot_warnings = [w for r in robots for w in r.warnings]  # with the robot file's own path
    return CheckedTask(config, doc, robots, robot_warnings + warnings)


def _check_pick_place(doc: YamlDocument, task: PickPlaceTask, robot: CheckedRobot,
                      problems: list[Problem], warnings: list[Problem]) -> None:
    arm = robot.config.arms[0]
    g = arm.gripper
    if g is None:
        problems.append(doc.problem(("robots", 0), f"robot {robot.config.name!r} has no gripper (arms[0].gripper is missing in {robot.path}); pick-place needs one"))
        return
    for problem in check_object_fit(doc, task, robot, arm) + check_grip_force(doc, task, robot, arm):
        (warnings if problem.severity == "warning" else problems).append(problem)
    place = np.asarray(task.pick_place.place_position)
    for k, ob in enumerate(task.scene.obstacles):
        half = np.asarray(ob.size if ob.shape == "box" else [ob.size[0] * 2] * 3) / 2
        if np.all(np.abs(place[:2] - np.asarray(ob.position[:2])) <= half[:2]):
            warnings.append(doc.problem(("pick_place", "place_position"), f"place position is inside obstacle {ob.name!r} (scene.obstacles[{k}])", "warning"))

