"""What one pick-place run prepares before its episodes: each episode's randomised setup
(:class:`EpisodeSetup`), the helpers every episode shares (:class:`_Tools`: kinematic model,
limits, the reactive or planned drive, the object's and gripper's measured geometry), and the
record of an episode refused before simulating.

Kept apart from the state machine (:mod:`robocfg.runners.pick_place_machine`), which runs one
episode with them; :mod:`robocfg.runners.pick_place_many` builds the same tools.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from robocfg.assets.object_shape import ObjectShape
from robocfg.checks.grip_force import PadForce
from robocfg.config.commands import PickPlaceParams
from robocfg.config.scene import Body
from robocfg.geometry import quat_to_matrix
from robocfg.grasp.gripper_model import GripperBoxes
from robocfg.runners.pick_place_report import EpisodeResult

if TYPE_CHECKING:
    from robocfg.sim.world import World

SUCTION_PRESS = 0.002  # m: a suction cup is driven this far into the top face


@dataclass(frozen=True)
class EpisodeSetup:
    """What an episode randomised: object body, its yaw (rad), place point (x, y in m), seed."""

    index: int
    seed: int
    body: Body
    yaw: float  # rad
    place_xy: np.ndarray


@dataclass(frozen=True)
class _Tools:
    """Per-run helpers shared by every episode: kinematic model, scaled joint limits, with
    ``motion: reactive`` the follow-target controller driving the free-space moves (with ``motion:
    planned``, the global planner), the object's geometry
    (:class:`~robocfg.assets.object_shape.ObjectShape`; None: read from the episode's body) and the
    parallel gripper's measured boxes (:class:`~robocfg.grasp.gripper_model.GripperBoxes`; None for
    suction) and pad force (:class:`~robocfg.checks.grip_force.PadForce`; None for suction)."""

    model: Any
    limits: Any
    reactive: Any = None
    planned: Any = None  # motion: planned — a robocfg.planning.drive.PlannedDrive
    shape: ObjectShape | None = None
    boxes: GripperBoxes | None = None
    pad_force: PadForce | None = None  # each pad's normal force at the force limit (parallel grippers)


def reactive_drive(robot, world: World, arm_name: str, params: PickPlaceParams, shape: ObjectShape):
    """The controller for ``motion: reactive`` (built once per run: it is expensive), else None."""
    if params.motion != "reactive":
        return None
    from robocfg.motion.reactive_drive import build_reactive_drive

    # the held object's centre beyond the TCP along the tool axis (m), and its bounding radius (m)
    top = float(shape.posed(quat_to_matrix(params.object.quaternion_xyzw()))[:, 2].max())
    beyond = top - SUCTION_PRESS if world.robot.arm(arm_name).require_gripper().grasps_at_surface else 0.0
    radius = float(np.max(np.linalg.norm(shape.vertices, axis=1)))
    return build_reactive_drive(robot, world, arm_name, velocity_scale=params.speed_scale, payload=(beyond, radius))


def not_simulated(s: EpisodeSetup, phase: str, reason: str) -> EpisodeResult:
    """The record of an episode failed before simulating (the object never moved)."""
    start = [round(float(v), 6) for v in s.body.position]
    return EpisodeResult(
        index=s.index, seed=s.seed, success=False, failed_phase=phase, reason=reason, object_start=start,
        object_start_yaw_deg=round(math.degrees(s.yaw), 4), place_target=[round(float(v), 6) for v in s.place_xy],
        object_final=start, place_error=round(float(np.linalg.norm(np.asarray(start[:2]) - s.place_xy)), 6),
        tilt_deg=0.0, lift_rise=None, mass=round(s.body.mass, 6), friction=round(s.body.friction, 6),
        sim_time=0.0, steps=0, phases=[])


def planned_drive(robot, world: World, model, params: PickPlaceParams):
    """The global planner for ``motion: planned`` (built once per run), else None."""
    if params.motion != "planned":
        return None
    from robocfg.planning.drive import build_planned_drive

    return build_planned_drive(robot, world, model)
