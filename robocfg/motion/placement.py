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

An arm that reaches the task's support at no distance (its base mounted too high above the floor
the spots lie on, like a torso-lift robot's) gets a raised work surface instead of a refusal: a
stand (a ``block`` fixture, named ``STAND``: a slab ``STAND_THICKNESS`` thick, a table top whose
legs are left out so it cannot meet the robot's own base) under both spots and their
randomisation regions. Its top is at the lowest of ``STAND_HEIGHTS`` (fractions of the arm
base's height above the support, tried from the top down) where the arm's reach towards the
spots is within ``STAND_REACH`` of the largest found: the reach grows as the surface rises
towards the arm base, and a surface a little lower lets the arm work from above it. The spots
are scaled by that reach and the output line says so (height, footprint).

Frames: world, metres.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from robocfg.assets.object_shape import object_shape
from robocfg.checks.robot import CheckedRobot, load_robot
from robocfg.checks.task import CheckedTask
from robocfg.config.commands import PickPlaceParams
from robocfg.config.fixtures import BlockFixture
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
    stand: BlockFixture | None = None  # the raised work surface to add to the scene (see with_stand)


STAND = "placement_stand"  # the stand's name (its one part: placement_stand/block)
STAND_HEIGHTS = (1.0, 0.9, 0.8, 0.7, 0.6, 0.5)  # of the arm base's height above the support, top down
STAND_REACH = 0.95  # a lower stand top is taken while the reach there is within this fraction of the best
STAND_THICKNESS = 0.05  # m
STAND_MARGIN = 0.03  # m of stand beyond the object's randomisation region (and the place point)
STAND_COLOR = [0.62, 0.52, 0.42, 1.0]


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


_MEMO: dict[tuple[str, ...], Placement] = {}  # the last few answers: a run checks, then builds its session
MEMO_SIZE = 8


def resolve_placement(task: CheckedTask, arm: str | None = None) -> Placement:
    """The task's spots in world coordinates for ``arm`` and the reach problems left with them
    (remembered for the same task config, robot and arm: ``run`` asks before and after checking).

    The key is the task's validated config, not its YAML document: a caller may run a copy of a
    checked task with changed parameters (``dataclasses.replace(task, config=...)``, as the API
    and tests do), and the answer carries those parameters."""
    robot = task.robots[0].config
    key = (str(task.path), repr(task.config), repr(robot), robot.arm(arm).name, str(task.written_robot))
    if key not in _MEMO:
        if len(_MEMO) >= MEMO_SIZE:
            _MEMO.pop(next(iter(_MEMO)))
        _MEMO[key] = _resolve(task, arm)
    return _MEMO[key]


def _resolve(task: CheckedTask, arm: str | None) -> Placement:
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
    if ours <= 0.0 < theirs:  # the arm cannot get down to the support: raise the work surface
        return _on_a_stand(task, arm, params, base, direction, theirs, task_robot.config.name)
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


def with_stand(task: CheckedTask, stand: BlockFixture | None) -> CheckedTask:
    """``task`` with ``stand`` among its scene's fixtures (``task`` itself when there is none)."""
    if stand is None:
        return task
    scene = task.config.scene
    config = task.config.model_copy(update={"scene": scene.model_copy(update={"fixtures": [*scene.fixtures, stand]})})
    return replace(task, config=config)


def _on_a_stand(task: CheckedTask, arm: str | None, params: PickPlaceParams, base: np.ndarray,
                direction: np.ndarray | None, theirs: float, their_name: str) -> Placement:
    """The spots on a stand whose top is where the arm reaches furthest towards them (see the
    module doc); the reach problems checked with the stand in the scene."""
    from robocfg.motion.reach import pick_place_reach, support_height

    obj = params.object
    xy = np.array([obj.position[:2], params.place_position[:2]], float)
    support = max(support_height(task.config.scene, x, y, task.path.parent) for x, y in xy)
    top = _arm_base_height(task, arm) - support
    best, ours, height = 0.0, 0.0, support
    for f in STAND_HEIGHTS if top > 0 else ():
        r = arm_reach(task, arm, direction=direction, support_z=support + f * top)
        best = max(best, r)
        if r < STAND_REACH * best:
            break  # lower still, the reach only shrinks
        if r > 0.0:
            ours, height = r, support + f * top
    name = task.robots[0].config.name
    if ours <= 0.0:
        return Placement(params, pick_place_reach(task, arm, params),
                         f"placement auto: {name} reaches no stand top between the support and its arm base "
                         "(tool pointing down), so the spots were not moved; the task needs a support that arm reaches")
    ratio = ours / theirs
    spots = base + ratio * (xy - base)
    params = params.model_copy(update={"object": obj.model_copy(update={"position": [*map(float, spots[0]), obj.position[2]]}),
                                       "place_position": [*map(float, spots[1]), params.place_position[2]]})
    half = object_shape(obj, task.path.parent).posed(quat_to_matrix(obj.quaternion_xyzw()))[:, :2]
    reach_out = float(np.max(np.linalg.norm(half - half.mean(axis=0), axis=1)))  # the object turned any way
    region = np.asarray(params.randomize.object.xy_range, float)
    pad = np.array([region + reach_out, np.asarray(params.randomize.place.xy_range, float) + reach_out]) + STAND_MARGIN
    lo, hi = (spots - pad).min(axis=0), (spots + pad).max(axis=0)
    thick = min(STAND_THICKNESS, height - support)
    stand = BlockFixture(type="block", name=STAND, size=[float(hi[0] - lo[0]), float(hi[1] - lo[1]), float(thick)],
                         position=[float((lo[0] + hi[0]) / 2), float((lo[1] + hi[1]) / 2), float(height - thick)],
                         color=list(STAND_COLOR))
    note = (f"placement auto: {name} cannot reach the support at {support:.2f} m (its arm base is "
            f"{top + support:.2f} m up), so the spots stand on a {stand.size[0]:.2f} x {stand.size[1]:.2f} m stand "
            f"('{STAND}', a slab {thick * 100:.0f} cm thick) with its top {height:.2f} m high, where it reaches "
            f"{ours:.2f} m (best {best:.2f} m; the task's robot "
            f"{their_name}: {theirs:.2f} m on the support, x{ratio:.2f} about the base): object at "
            f"[{spots[0][0]:.3f}, {spots[0][1]:.3f}] m, place at [{spots[1][0]:.3f}, {spots[1][1]:.3f}] m")
    return Placement(params, pick_place_reach(with_stand(task, stand), arm, params), note, stand)


def _arm_base_height(task: CheckedTask, arm: str | None) -> float:
    """World height (m) of the arm's ``base_link`` at its home pose."""
    from robocfg.kinematics.model import KinematicModel

    robot = task.robots[0]
    arm_cfg = robot.config.arm(arm)
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=pose_matrix(task.config.robots[0]))
    return float(model.fk(np.asarray(arm_cfg.home, float), arm_cfg.base_link)[2, 3])


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
              direction: np.ndarray | None = None, support_z: float | None = None) -> float:
    """The arm's reach (m): the farthest horizontal distance from the base along ``direction``
    (world; default: straight ahead, as mounted) at which the tool pointing down reaches the
    object's grasp height and the pre-grasp height. ``robot``: another robot on the task's mount
    (default: the task's first robot); ``support_z``: the object rests at this height (m)
    everywhere (default: on the scene's support below each point)."""
    from robocfg.kinematics.chain_bound import ChainBound
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
    bound = ChainBound.of(model)  # poses the chain cannot stretch to are not asked of IK (same answer, no IK time)

    def reachable(d: float) -> bool:
        p = T_base[:3, 3] + d * forward
        z = (support_height(task.config.scene, p[0], p[1], task.path.parent) if support_z is None else support_z) + grip
        down = np.array([0.0, 0.0, -1.0])
        for height in (z + params.above_height, z):
            ok = False
            for a in (0.5 * math.pi, 0.0):  # fingers closing across, then along, the forward direction
                closing = math.cos(a) * forward + math.sin(a) * np.array([-forward[1], forward[0], 0.0])
                g = Grasp(np.array([p[0], p[1], height]), grasp_rotation(down, closing), 0.0)
                T = ee_pose_from_grasp(g, arm_cfg)
                if bound.may_reach(T) and model.ik(T, seed_q=home, frame="ee", time_budget=IK_BUDGET).converged:
                    ok = True
                    break
            if not ok:
                return False
        return True

    return farthest_reachable(reachable, far)
