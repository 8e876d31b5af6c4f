"""The follow-target controller as a point-to-point drive for :class:`~robocfg.motion.moves.ArmMover`.

Pick-place's ``motion: reactive`` drives its free-space moves (pre-grasp, transport) with the
:class:`~robocfg.motion.reactive.ReactiveController`: every control period the target EE pose is
converted to the TCP pose the controller servos to, the controller's joint positions and
velocities go to the drives, and the arm keeps ``margin`` m from the task's scene (ground, table,
pedestal, ``scene.obstacles`` and fixtures; mesh bodies as the convex hulls the planner sees). Building the controller loads the URDF into placo and convex-hulls
every collision mesh: build it once per run with :func:`build_reactive_drive`.

A held object is not part of the task scene, so it would be dragged over or into obstacles: give
``payload`` and a sphere bounding it is attached to the EE link (for every move, so pre-grasp is
slightly more conservative than it needs to be).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.config.scene import Body
    from robocfg.motion.reactive import ReactiveController
    from robocfg.sim.world import World

REACTIVE_RATE = 120.0  # Hz: control rate of the free-space moves
REACTIVE_MARGIN = 0.02  # m kept between the arm and the environment
REACTIVE_MAX_SPEED = 0.5  # m/s: cap on the commanded TCP speed


@dataclass
class ReactiveDrive:
    """A built controller: ``substeps`` physics steps per control step; ``T_ee_tcp`` (4×4) maps the
    EE poses the movers use to the TCP poses the controller servos to."""

    controller: ReactiveController
    substeps: int
    T_ee_tcp: np.ndarray
    skipped: list[str]  # scene bodies the controller cannot avoid (none since meshes are convex hulls)


def bounding_radius(body: Body) -> float:
    """Radius (m) of the sphere around a ``Body``'s centre that contains it."""
    s = body.size
    if body.shape in ("box", "mesh"):
        return float(np.linalg.norm(s)) / 2
    if body.shape == "sphere":
        return float(s[0])
    if body.shape == "cylinder":
        return float(np.hypot(s[0], s[1] / 2))
    return float(s[0] + s[1] / 2)  # capsule


def build_reactive_drive(robot: CheckedRobot, world: World, arm_name: str, velocity_scale: float = 1.0,
                         payload: tuple[float, float] | None = None,
                         rate: float = REACTIVE_RATE, margin: float = REACTIVE_MARGIN,
                         max_speed: float = REACTIVE_MAX_SPEED) -> ReactiveDrive:
    """Controller for arm ``arm_name`` of ``robot`` (a CheckedRobot) in ``world``'s task scene;
    ``velocity_scale`` scales the joint velocity limits (rad/s); ``payload`` = (distance of the held
    object's centre beyond the TCP along ``ee_axis``, bounding radius), both m."""
    from robocfg.collision import LinkGeometry
    from robocfg.config.types import AXIS_INDEX
    from robocfg.motion.reactive import ReactiveController, ReactiveSettings
    from robocfg.motion.reactive.setup import MeshPoses, arm_spec, scene_shapes
    from robocfg.sim.loading import prepared_urdf

    substeps = max(1, round(1.0 / (rate * world.dt)))
    spec = arm_spec(robot, prepared_urdf(robot), world.robot.base_pose(), arm_name, velocity_scale=velocity_scale)
    if payload is not None:
        arm_cfg = robot.config.arm(arm_name)
        origin = np.eye(4)
        origin[AXIS_INDEX[arm_cfg.ee_axis], 3] = arm_cfg.tcp_offset + payload[0]
        held = LinkGeometry(arm_cfg.ee_link, "sphere", origin, (payload[1],))
        spec = replace(spec, collision=[*(spec.collision or []), held])
    env, skipped = scene_shapes(world.task.config.scene, MeshPoses.of(world))
    settings = ReactiveSettings(dt=substeps * world.dt, margin=margin, max_linear_speed=max_speed)
    return ReactiveDrive(ReactiveController(spec, env, settings), substeps, np.asarray(spec.T_ee_tcp, float), skipped)
