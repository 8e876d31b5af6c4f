"""Pick-place spots given relative to the robot (``placement: reach`` / ``auto``), turned into world points.

With ``placement: reach`` a task gives ``object.position`` and ``place_position`` as (x, y) in the
robot's base frame (x forward, as mounted) in units of the arm's *reach*: the farthest horizontal
distance from the base at which the tool, pointing straight down, reaches the object's grasp
height and the pre-grasp height above it (IK, before simulating). So ``[0.6, -0.2]`` is 60 % of
the reach forward and 20 % to the right, for a desk arm and for an industrial arm on a pedestal
alike; the randomisation ranges stay in metres (they are about the object, not the robot).

With ``placement: auto`` the spots are world coordinates written for the robot the file names;
when the robot that runs the task (``--robot``) reaches them (the IK reach check), nothing changes
and no reach is measured. When it does not, both arms' reaches are measured towards the spots
(from the base to the middle of the two spots, so an arm mounted sideways or a lift-mounted arm is
measured where the task needs it) and the spots' x, y are scaled about the base by their ratio;
z and the randomisation ranges are kept.

Frames: world, metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from robocfg.assets.object_shape import object_shape
from robocfg.checks.robot import CheckedRobot, load_robot
from robocfg.checks.task import CheckedTask
from robocfg.config.commands import PickPlaceParams
from robocfg.config.robot import SuctionGripperConfig
from robocfg.geometry import pose_matrix, quat_to_matrix
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp, grasp_rotation

FK_SAMPLES = 400  # random configurations bounding how far the tool can get from the base
IK_BUDGET = 0.2  # s per IK query; not consulted: bound_ik_by_iterations ends the search by count


@dataclass(frozen=True)
class Placement:
    """A pick-place task's parameters with world positions (``params``), the unreachable poses
    found for them (``reach``, see ``robocfg.motion.reach``) and a line saying how the spots were
    moved (``note``; empty when they were not)."""

    params: PickPlaceParams
    reach: list = field(default_factory=list)  # list[ReachProblem]
    note: str = ""


SCAN_STEPS = 24  # distances tried from the far bound inwards
REFINE_STEPS = 6  # bisection steps between the last reachable and the first unreachable distance


def farthest_reachable(reachable: Callable[[float], bool], far: float) -> float:
    """The largest distance ``d`` ≤ ``far`` (m) with ``reachable(d)``: scanned inwards from ``far``
    in ``SCAN_STEPS`` steps, then bisected ``REFINE_STEPS`` times towards the first unreachable
    distance beyond it; 0.0 when none is reachable. Scanning from outside in finds the outermost
    reachable distance even where nearer ones are unreachable (close to the base)."""
    good, bad = None, far
    for d in np.linspace(far, far / SCAN_STEPS, SCAN_STEPS):
        if reachable(float(d)):
            good = float(d)
            break
        bad = float(d)
    if good is None:
        return 0.0
    for _ in range(REFINE_STEPS):
        mid = (good + bad) / 2
        good, bad = (mid, bad) if reachable(mid) else (good, mid)
    return good


def resolved_params(task: CheckedTask, arm: str | None = None) -> PickPlaceParams:
    """The task's pick-place parameters with world positions: as given for ``placement: world``,
    converted from the robot frame and reach units for ``placement: reach``, scaled to the running
    robot's reach for ``placement: auto`` when it cannot reach them as written."""
    return resolve_placement(task, arm).params


def resolve_placement(task: CheckedTask, arm: str | None = None) -> Placement:
    """The task's spots in world coordinates for ``arm`` and the reach problems left with them."""
    from robocfg.motion.reach import pick_place_reach

    params: PickPlaceParams = task.config.pick_place  # type: ignore[union-attr]
    if params.placement == "reach":
        params = _from_reach_units(task, params, arm)
    if params.placement != "auto":
        return Placement(params, pick_place_reach(task, arm, params))
    params = params.model_copy(update={"placement": "world"})
    reach = pick_place_reach(task, arm, params)
    written = task.written_robot
    robot = task.robots[0]
    if not any(r.nominal for r in reach) or written is None or written.resolve() == robot.path.resolve():
        return Placement(params, reach)
    T = pose_matrix(task.config.robots[0])
    base = T[:2, 3]
    spots = np.array([params.object.position[:2], params.place_position[:2]], float)
    toward = spots.mean(axis=0) - base
    direction = np.array([*toward, 0.0]) if np.linalg.norm(toward) > 1e-6 else None
    task_robot = load_robot(written)
    theirs = arm_reach(task, None, robot=task_robot, direction=direction)
    ours = arm_reach(task, arm, direction=direction)
    if theirs <= 0.0 or ours <= 0.0:  # no scale helps: the reach problems say where it fails
        who = robot.config.name if ours <= 0.0 else f"the task's robot {task_robot.config.name}"
        return Placement(params, reach, f"placement auto: {who} reaches the object's support height at no distance "
                                        "towards the spots (tool pointing down), so they were not scaled; the task "
                                        "needs a support that arm reaches")
    ratio = ours / theirs

    def scaled(p) -> list[float]:
        xy = base + ratio * (np.asarray(p[:2], float) - base)
        return [float(xy[0]), float(xy[1]), float(p[2])]

    obj = params.object
    params = params.model_copy(update={"object": obj.model_copy(update={"position": scaled(obj.position)}),
                                       "place_position": scaled(params.place_position)})
    name = robot.config.name
    note = (f"placement auto: spots scaled to {name}'s reach ({ours:.2f} m, the task's robot "
            f"{task_robot.config.name}: {theirs:.2f} m, x{ratio:.2f} about the base): object at "
            f"[{params.object.position[0]:.3f}, {params.object.position[1]:.3f}] m, place at "
            f"[{params.place_position[0]:.3f}, {params.place_position[1]:.3f}] m")
    return Placement(params, pick_place_reach(task, arm, params), note)


def _from_reach_units(task: CheckedTask, params: PickPlaceParams, arm: str | None) -> PickPlaceParams:
    """``placement: reach``: x, y in the base frame in units of the arm's reach, as world points."""
    mount = task.config.robots[0]
    T = pose_matrix(mount)
    forward = T[:3, 0].copy()
    forward[2] = 0.0
    forward = forward / np.linalg.norm(forward) if np.linalg.norm(forward) > 1e-9 else np.array([1.0, 0.0, 0.0])
    left = np.array([-forward[1], forward[0], 0.0])
    reach = arm_reach(task, arm)

    def world(xy) -> list[float]:
        p = T[:3, 3] + reach * (xy[0] * forward + xy[1] * left)
        return [float(p[0]), float(p[1])]

    obj = params.object
    return params.model_copy(update={
        "placement": "world",
        "object": obj.model_copy(update={"position": [*world(obj.position), obj.position[2]]}),
        "place_position": [*world(params.place_position), params.place_position[2]],
    })


def arm_reach(task: CheckedTask, arm: str | None = None, robot: CheckedRobot | None = None,
              direction: np.ndarray | None = None) -> float:
    """The arm's reach (m): the farthest horizontal distance from the base along ``direction``
    (world; default: straight ahead, as mounted) at which the tool pointing down reaches the
    object's grasp height and the pre-grasp height. ``robot``: another robot on the task's mount
    (default: the task's first robot)."""
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import bound_ik_by_iterations
    from robocfg.motion.reach import support_height

    params: PickPlaceParams = task.config.pick_place  # type: ignore[union-attr]
    robot = task.robots[0] if robot is None else robot
    arm_cfg = robot.config.arm(arm)
    T_base = pose_matrix(task.config.robots[0])
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=T_base)
    bound_ik_by_iterations(model)
    rng = np.random.default_rng(0)
    q = rng.uniform(model.lower, model.upper, size=(FK_SAMPLES, len(model.lower)))
    far = max(float(np.linalg.norm(model.fk(qi, "ee")[:2, 3] - T_base[:2, 3])) for qi in q)
    far += abs(arm_cfg.tcp_offset)
    forward = (T_base[:3, 0] if direction is None else np.asarray(direction, float)).copy()
    forward[2] = 0.0
    forward /= max(np.linalg.norm(forward), 1e-9)
    obj = params.object
    shape = object_shape(obj, task.path.parent)
    R0 = quat_to_matrix(obj.quaternion_xyzw())
    grip = shape.below_origin(R0) + (shape.posed(R0)[:, 2].max() if isinstance(arm_cfg.gripper, SuctionGripperConfig) else 0.0)
    home = np.asarray(arm_cfg.home, float)

    def reachable(d: float) -> bool:
        p = T_base[:3, 3] + d * forward
        z = support_height(task.config.scene, p[0], p[1], task.path.parent) + grip
        down = np.array([0.0, 0.0, -1.0])
        for height in (z + params.above_height, z):
            ok = False
            for a in (0.5 * math.pi, 0.0):  # fingers closing across, then along, the forward direction
                closing = math.cos(a) * forward + math.sin(a) * np.array([-forward[1], forward[0], 0.0])
                g = Grasp(np.array([p[0], p[1], height]), grasp_rotation(down, closing), 0.0)
                if model.ik(ee_pose_from_grasp(g, arm_cfg), seed_q=home, frame="ee", time_budget=IK_BUDGET).converged:
                    ok = True
                    break
            if not ok:
                return False
        return True

    return farthest_reachable(reachable, far)
