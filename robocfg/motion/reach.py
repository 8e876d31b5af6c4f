"""Can the arm reach where a pick-place task asks it to go? Checked by IK before simulating.

For the object's spot and the place spot (their nominal points and the corners of their
randomisation regions) the tool pointing straight down is asked for at the grasp height and at
the pre-grasp / carrying height above it, turned about the vertical in ``YAW_STEPS`` steps (any
turn that IK reaches will do). Heights come from the object's real geometry resting on the support
below the spot (the highest static surface there: table, pedestal, fixture, obstacle, else the
ground). A nominal point out of reach fails the run before it starts (the phase that would fail
is named); a region corner out of reach is a warning (some randomised episodes would fail).

Frames: world, metres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import product
from pathlib import Path

import numpy as np

from robocfg.assets.object_shape import object_shape
from robocfg.assets.paths import UnresolvedPath
from robocfg.checks.task import CheckedTask
from robocfg.config.commands import PickPlaceParams
from robocfg.config.robot import SuctionGripperConfig
from robocfg.config.scene import Scene
from robocfg.errors import Problem
from robocfg.geometry import pose_matrix, quat_to_matrix
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp, grasp_rotation

YAW_STEPS = 6  # tool turns about the vertical tried over half a turn
IK_BUDGET = 0.2  # s of wall clock per IK query; not consulted: bound_ik_by_iterations ends the search by count
WORLD_HINT = ("the spots are world coordinates: give them relative to the arm with 'placement: reach' "
              "(as the built-in task pick_place_reach does)")


@dataclass(frozen=True)
class ReachProblem:
    """A pose the arm cannot reach: the ``phase`` that would fail, what it is (``what``), the TCP
    point (m, world), the IK residual (m), whether it is the nominal point (``nominal``: the run
    cannot succeed) and the YAML location of the spot."""

    phase: str
    what: str
    point: tuple[float, float, float]
    residual: float
    nominal: bool
    loc: tuple[str | int, ...]
    hint: str = ""  # what to do about it, appended to the reason

    @property
    def reason(self) -> str:
        x, y, z = self.point
        where = "nominal point" if self.nominal else "a corner of its randomisation region"
        return (f"{self.what} is unreachable, out of the arm's reach ({where}, TCP at [{x:.3f}, {y:.3f}, {z:.3f}] m, "
                f"IK residual {self.residual * 1000:.0f} mm)" + (f"; {self.hint}" if self.hint else ""))

    def problem(self, task: CheckedTask) -> Problem:
        return task.doc.problem(self.loc, f"{self.phase}: {self.reason}", "warning")


def pick_place_reach(task: CheckedTask, arm: str | None = None, params: PickPlaceParams | None = None) -> list[ReachProblem]:
    """Every unreachable pose of the pick-place task ``task`` for ``arm`` (default: the first);
    ``params``: its parameters with world positions (default: resolved from the task)."""
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import bound_ik_by_iterations
    from robocfg.motion.placement import resolved_params

    params = resolved_params(task, arm) if params is None else params
    robot = task.robots[0]
    arm_cfg = robot.config.arm(arm)
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=pose_matrix(task.config.robots[0]))
    bound_ik_by_iterations(model)
    home = np.asarray(arm_cfg.home, float)
    obj = params.object
    shape = object_shape(obj, task.path.parent)
    R0 = quat_to_matrix(obj.quaternion_xyzw())
    centre_above_support = shape.below_origin(R0)
    suction = isinstance(arm_cfg.gripper, SuctionGripperConfig)
    grip_above_support = centre_above_support + (shape.posed(R0)[:, 2].max() if suction else 0.0)
    scene = task.config.scene
    given: PickPlaceParams = task.config.pick_place  # type: ignore[union-attr]
    hint = WORLD_HINT if given.placement == "world" else ""
    out: list[ReachProblem] = []
    spots = [("object", obj.position[:2], params.randomize.object.xy_range, ("pick_place", "object", "position"),
              ("approach", "the grasp pose"), ("pre_grasp", "the pose above the object"), params.above_height),
             ("place", params.place_position[:2], params.randomize.place.xy_range, ("pick_place", "place_position"),
              ("lower", "the place pose"), ("transport", "the pose above the place point"), params.lift_height)]
    for _, xy0, rng, loc, (low_phase, low_what), (high_phase, high_what), rise in spots:
        for nominal, (sx, sy) in [(True, (0.0, 0.0)), *((False, c) for c in product((-1.0, 1.0), repeat=2))]:
            if not nominal and (not any(rng) or (out and out[-1].loc == loc)):
                break  # no region, or the nominal point already fails: corners add nothing
            x, y = xy0[0] + sx * rng[0], xy0[1] + sy * rng[1]
            z = support_height(scene, x, y, task.path.parent) + grip_above_support
            for phase, what, height in ((high_phase, high_what, z + rise), (low_phase, low_what, z)):
                residual = _best_residual(model, arm_cfg, home, np.array([x, y, height]))
                if residual is not None:
                    out.append(ReachProblem(phase, what, (x, y, height), residual, nominal, loc, hint))
                    break  # the first pose the run would fail at (the higher one comes first)
    return out


def _best_residual(model, arm_cfg, home: np.ndarray, point: np.ndarray) -> float | None:
    """None when some tool turn about the vertical reaches ``point`` pointing down, else the
    smallest IK position residual (m)."""
    best = math.inf
    down = np.array([0.0, 0.0, -1.0])
    for k in range(YAW_STEPS):
        a = math.pi * k / YAW_STEPS
        g = Grasp(point, grasp_rotation(down, np.array([math.cos(a), math.sin(a), 0.0])), 0.0)
        res = model.ik(ee_pose_from_grasp(g, arm_cfg), seed_q=home, frame="ee", time_budget=IK_BUDGET)
        if res.converged:
            return None
        best = min(best, float(res.pos_err))
    return best


def support_height(scene: Scene, x: float, y: float, base_dir: Path | None = None) -> float:
    """Height (m) of the highest static surface at (x, y): the table, the pedestal, static scene
    objects (mass 0), obstacles and fixture parts (a bin's floor, a shelf's level), else the ground (0)."""
    from robocfg.config.scene import Body

    statics: list[Body] = [*(o for o in scene.objects if o.mass == 0), *scene.obstacles, *scene.fixture_parts()]
    t = scene.table
    if t is not None:
        statics.append(Body(name="table", shape="box", size=list(t.size), quat_xyzw=list(t.quaternion_xyzw()),
                            position=[t.position[0], t.position[1], t.position[2] - t.size[2] / 2]))
    ped = scene.pedestal
    if ped is not None:
        statics.append(Body(name="pedestal", shape="cylinder", size=[ped.radius, ped.height],
                            quat_xyzw=list(ped.quaternion_xyzw()),
                            position=[ped.position[0], ped.position[1], ped.position[2] - ped.height / 2]))
    z = 0.0
    for body in statics:
        try:
            shape = object_shape(body, base_dir or Path("."))
        except (UnresolvedPath, ValueError):
            continue  # a missing mesh is reported by the task checks
        top = shape.top_at(quat_to_matrix(body.quaternion_xyzw()), body.position, x, y)
        if top is not None:
            z = max(z, top)
    return z
