"""Checks of a task's command block against its scene and robot that need no simulation.

Everything here used to surface only while a run was under way (sometimes after episodes had
finished): a missing mesh file, ``hold_object`` naming no scene object, waypoints outside the
joint limits, a grasp task with nothing to grasp. ``validate`` and every ``run`` call these
through :func:`robocfg.checks.task.load_task`, so they stop a run before it simulates.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

import numpy as np

from robocfg.assets.paths import UnresolvedPath, body_asset
from robocfg.checks.drives import missing_velocity_limits
from robocfg.checks.robot import CheckedRobot
from robocfg.checks.waypoints import PositionLimits, check_joint_waypoints
from robocfg.config.load import Loc, YamlDocument
from robocfg.config.robot import ParallelGripperConfig, SuctionGripperConfig
from robocfg.config.scene import Body
from robocfg.config.task import PickPlaceTask
from robocfg.errors import Problem
from robocfg.suggest import did_you_mean

if TYPE_CHECKING:  # made when a task of their kind is validated (robocfg.config.task): told apart by kind
    from robocfg.config.task import (
        GraspTask,
        GripperTask,
        TaskConfig,
        TrajectoryTask,
    )


def check_task_params(doc: YamlDocument, task: TaskConfig, robot: CheckedRobot) -> list[Problem]:
    """Every problem of the task's bodies and command block; ``robot`` runs the command."""
    problems = _check_meshes(doc, task)
    problems += _unique_names(doc, [(("scene", key, k), b.name) for key in ("objects", "obstacles")
                                    for k, b in enumerate(getattr(task.scene, key))], taken=set())
    if task.task == "gripper":
        problems += _check_gripper(doc, task, robot)
    elif task.task == "trajectory":
        problems += _check_trajectory(doc, task, robot)
    elif task.task == "grasp":
        problems += _check_grasp(doc, task, robot)
    elif isinstance(task, PickPlaceTask):
        problems += _unique_against_scene(doc, task, [(("pick_place", "object"), task.pick_place.object.name)])
        problems += _timed_arm(robot, None)
    elif task.task == "pick_place_many":
        objects = task.pick_place_many.objects
        problems += _unique_against_scene(doc, task, [(("pick_place_many", "objects", k), o.name) for k, o in enumerate(objects)])
        problems += _timed_arm(robot, None)
    elif task.task == "follow_target":
        obstacles = task.follow_target.obstacles
        problems += _unique_against_scene(doc, task, [(("follow_target", "obstacles", k), o.name) for k, o in enumerate(obstacles)])
    return problems


def _bodies(task: TaskConfig) -> Iterator[tuple[Loc, Body]]:
    """Every body the task may spawn, with its location in the YAML."""
    for key in ("objects", "obstacles"):
        for k, b in enumerate(getattr(task.scene, key)):
            yield ("scene", key, k), b
    if isinstance(task, PickPlaceTask):
        yield ("pick_place", "object"), task.pick_place.object
    if task.task == "grasp":
        for k, b in enumerate(task.grasp.objects):
            yield ("grasp", "objects", k), b
    if task.task == "pick_place_many":
        for k, b in enumerate(task.pick_place_many.objects):
            yield ("pick_place_many", "objects", k), b


def _check_meshes(doc: YamlDocument, task: TaskConfig) -> list[Problem]:
    out = []
    for loc, body in _bodies(task):
        if body.shape != "mesh" or not body.mesh:
            continue
        try:
            body_asset(body.mesh, doc.path.parent)
        except UnresolvedPath as exc:
            out.append(doc.problem((*loc, "mesh"), f"mesh file of {body.name!r} not found: {exc}"))
    return out


def _unique_against_scene(doc: YamlDocument, task: TaskConfig, named: list[tuple[Loc, str]]) -> list[Problem]:
    """Bodies a command adds must not reuse a scene body's name (the world and the report key bodies by name)."""
    return _unique_names(doc, named, {b.name for b in [*task.scene.objects, *task.scene.obstacles]})


def _unique_names(doc: YamlDocument, named: list[tuple[Loc, str]], taken: set[str]) -> list[Problem]:
    """A problem at each ``name`` of ``named`` that is in ``taken`` or repeats an earlier one."""
    out, seen = [], set()
    for loc, name in named:
        if name in taken:
            out.append(doc.problem((*loc, "name"), f"name {name!r} is already used by a body in scene.objects/obstacles; names must be unique"))
        elif name in seen:
            out.append(doc.problem((*loc, "name"), f"name {name!r} is used twice; names must be unique"))
        seen.add(name)
    return out


def _check_gripper(doc: YamlDocument, task: GripperTask, robot: CheckedRobot) -> list[Problem]:
    g = robot.config.arms[0].gripper
    if g is None:
        return [doc.problem(("robots", 0), f"robot {robot.config.name!r} has no gripper (arms[0].gripper is missing in {robot.path}); "
                                           "'run gripper' needs one")]
    name = task.gripper.hold_object
    known = [b.name for b in task.scene.objects]
    if name is None and isinstance(g, SuctionGripperConfig):
        return [doc.problem(("gripper", "hold_object"), "a suction gripper is tested by holding an object: set gripper.hold_object "
                                                        f"to one of scene.objects (known: {', '.join(known) or 'none'})")]
    if name is not None and name not in known:
        return [doc.problem(("gripper", "hold_object"), f"no object {name!r} in scene.objects{did_you_mean(name, known)} "
                                                        f"(known: {', '.join(known) or 'none'})")]
    if name is not None and isinstance(g, ParallelGripperConfig):
        k = known.index(name)
        obj = task.scene.objects[k]
        narrow = narrowest_horizontal(obj.shape, obj.size)
        if narrow >= g.max_width:
            return [doc.problem(("scene", "objects", k, "size"),
                                f"hold_object {name!r} is {narrow * 1000:.1f} mm across its narrowest side, not less than the "
                                f"gripper's max_width {g.max_width * 1000:.1f} mm: the fingers cannot close on it")]
    return []


def narrowest_horizontal(shape: str, size: list[float]) -> float:
    """Narrowest horizontal extent (m) of a body as written in the YAML: the smaller of a box's
    (or mesh's bounding box's) x and y sizes, a sphere's or cylinder's diameter. A parallel
    gripper closing across a body needs an opening wider than this."""
    if shape in ("box", "mesh"):
        return min(size[0], size[1])
    return 2 * size[0]


def _check_trajectory(doc: YamlDocument, task: TrajectoryTask, robot: CheckedRobot) -> list[Problem]:
    params = task.trajectory
    arms = [a.name for a in robot.config.arms]
    if params.arm is not None and params.arm not in arms:
        return [doc.problem(("trajectory", "arm"), f"robot {robot.config.name!r} has no arm {params.arm!r}"
                                                   f"{did_you_mean(params.arm, arms)} (arms: {', '.join(arms)})")]
    arm = robot.config.arm(params.arm)
    names = robot.arm_joints(arm)
    joints = [robot.urdf.joints[n] for n in names]
    limits = PositionLimits(tuple(names), np.array([j.lower for j in joints]), np.array([j.upper for j in joints]),
                            np.array([j.type != "continuous" for j in joints]))
    return _timed_arm(robot, params.arm) + check_joint_waypoints(
        list(params.waypoints), limits, np.asarray(arm.home, dtype=float),
        lambda loc, msg: doc.problem(("trajectory", "waypoints", *loc), msg))


def _check_grasp(doc: YamlDocument, task: GraspTask, robot: CheckedRobot) -> list[Problem]:
    params = task.grasp
    out = []
    if not params.objects:
        out.append(doc.problem(("grasp", "objects") if "objects" in doc.data.get("grasp", {}) else ("grasp",),
                               "no objects to grasp: give at least one in grasp.objects"))
    if not any(isinstance(a.gripper, ParallelGripperConfig) for a in robot.config.arms):
        out.append(doc.problem(("robots", 0), f"'run grasp' plans two-finger antipodal grasps; robot {robot.config.name!r} "
                                              "has no arm with a parallel gripper"))
    out += _unique_against_scene(doc, task, [(("grasp", "objects", k), b.name) for k, b in enumerate(params.objects)])
    return out + _timed_arm(robot, None)


def _timed_arm(robot: CheckedRobot, arm: str | None) -> list[Problem]:
    """Problems of the arm ``arm`` (None: the first) for timed moves: each joint needs a velocity limit."""
    return missing_velocity_limits(robot, robot.arm_joints(robot.config.arm(arm)))
