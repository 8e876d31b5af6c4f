"""Parameter blocks of ``run pick-place`` and the joint limits' scale factors the trajectory kinds
share. Units: m, rad, s, N.

The other kinds' blocks live with their task models (``gripper_task``, ``trajectory_task``,
``follow_target_task``, ``grasp_task``), made only when used (``robocfg.config.task``); their names
stay importable from here (``from robocfg.config.commands import GraspParams`` imports
``grasp_task``).
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

import importlib
from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.scene import Body
from robocfg.config.types import (
    FiniteFloat,
    Frozen,
    NonNegFloat,
    PositiveFloat,
    Vec3,
)

if TYPE_CHECKING:
    from robocfg.config.follow_target_task import MOTION_TYPES as MOTION_TYPES
    from robocfg.config.follow_target_task import FollowObstacle as FollowObstacle
    from robocfg.config.follow_target_task import FollowTargetParams as FollowTargetParams
    from robocfg.config.follow_target_task import Motion as Motion
    from robocfg.config.grasp_task import Camera as Camera
    from robocfg.config.grasp_task import GraspParams as GraspParams
    from robocfg.config.grasp_task import Workspace as Workspace
    from robocfg.config.gripper_task import GripperParams as GripperParams
    from robocfg.config.trajectory_task import TrajectoryParams as TrajectoryParams
    from robocfg.config.trajectory_task import Waypoint as Waypoint

_ELSEWHERE = {  # name -> the module that defines it now
    **dict.fromkeys(("MOTION_TYPES", "Motion", "FollowObstacle", "FollowTargetParams"), "robocfg.config.follow_target_task"),
    **dict.fromkeys(("Camera", "Workspace", "GraspParams"), "robocfg.config.grasp_task"),
    "GripperParams": "robocfg.config.gripper_task",
    **dict.fromkeys(("TrajectoryParams", "Waypoint"), "robocfg.config.trajectory_task"),
}


def __getattr__(name: str) -> object:
    """The other kinds' parameter models, from their modules (imported on first use)."""
    if name in _ELSEWHERE:
        return getattr(importlib.import_module(_ELSEWHERE[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class Limits(Frozen):
    """Scale factors applied to the robot's velocity/acceleration/jerk limits."""

    velocity_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    acceleration_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    acceleration: PositiveFloat = Field(10.0, description="Default joint acceleration limit (rad/s²) when the robot YAML gives none.")
    jerk: PositiveFloat | None = Field(None, description="Optional jerk limit (rad/s³).")


class Region(Frozen):
    """An axis-aligned randomisation region around a nominal value."""

    xy_range: Annotated[list[NonNegFloat], Field(min_length=2, max_length=2)] = Field(
        default_factory=lambda: [0.0, 0.0], description="± half-ranges in x and y (m)."
    )
    yaw_range_deg: NonNegFloat = Field(0.0, description="± yaw range (deg).")


class PickPlaceRandomize(Frozen):
    """What ``--episodes`` randomises (episode 0 included when ranges are non-zero)."""

    object: Region = Field(default_factory=lambda: Region(xy_range=[0.08, 0.08], yaw_range_deg=45.0))
    place: Region = Field(default_factory=Region)
    mass_scale: NonNegFloat = Field(0.0, description="± fraction, e.g. 0.1 for ±10 %.")
    friction_scale: NonNegFloat = Field(0.0, description="± fraction.")


class PhaseTimeouts(Frozen):
    """Per-phase time limits (s): how long each phase may take before the episode fails in it. A
    motion phase without one gets its planned motion's duration plus a margin; grasp and release
    have no motion to plan and keep a fixed limit."""

    pre_grasp: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")
    approach: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")
    grasp: PositiveFloat = Field(1.5, description="Time (s) allowed for the fingers to close on the object.")
    lift: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")
    transport: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")
    lower: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")
    release: PositiveFloat = Field(1.5, description="Time (s) allowed for the object to come free.")
    retract: PositiveFloat | None = Field(None, description="Time limit (s) of this motion; leave it out to allow the planned motion's duration × 1.25 + 1 s, so a slow arm is not failed for being slow.")


class PickPlaceParams(Frozen):
    """``run pick-place``: the 8-phase pick-and-place state machine."""

    object: Body = Field(description="The object to pick (spawned resting on its support).")
    place_position: Vec3 = Field(description="Where the object's centre should end (m, world; see placement); z is ignored (it rests on the support).")
    placement: Literal["world", "reach", "auto"] = Field("world", description="world: object.position and place_position are world coordinates (m). auto: world coordinates written for the robot the file names; a robot that cannot reach them (--robot) gets them scaled about its base by the ratio of the two arms' reaches towards the spots (z and the randomisation ranges kept). reach: their x and y are in the robot's base frame (x forward, as mounted), in units of the arm's reach with the tool pointing down (e.g. [0.6, -0.2]), so one task fits a desk arm and an industrial arm alike; the randomisation ranges stay in metres.")
    randomize: PickPlaceRandomize = Field(default_factory=PickPlaceRandomize)
    above_height: PositiveFloat = Field(0.15, description="TCP height above the grasp point for pre-grasp/transport (m).")
    lift_height: PositiveFloat = Field(0.15, description="How far the object is lifted (m).")
    grasp_depth: FiniteFloat | None = Field(None, description="TCP height of the grasp relative to the object centre (m); leave it out to have it chosen from the object's and the gripper's geometry (mid-height, or near the top of a tall object so the palm stays clear).")
    position_tolerance: PositiveFloat = Field(0.005, description="Phase convergence: TCP position error (m).")
    orientation_tolerance: PositiveFloat = Field(0.05, description="Phase convergence: TCP orientation error (rad).")
    timeouts: PhaseTimeouts = Field(default_factory=PhaseTimeouts)
    motion: Literal["trajectory", "reactive", "planned"] = Field("trajectory", description="How the arm makes the free-space moves (pre-grasp, transport): 'trajectory' = IK + min-jerk timed joint trajectories; 'reactive' = the follow-target controller, which keeps the arm 2 cm clear of the scene (ground, table, pedestal, obstacles); 'planned' = a collision-free joint path (OMPL RRT-Connect, arm and held object 1 cm clear of the scene), shortened and toppra-timed. The short straight moves near the object always use IK + min-jerk.")
    speed_scale: Annotated[float, Field(gt=0, le=1)] = Field(0.5, description="Fraction of joint velocity limits used.")
    grip_force: PositiveFloat | None = Field(None, description="Overrides the gripper's max_force.")
    success_tolerance: PositiveFloat = Field(0.02, description="Horizontal place error allowed (m).")
    max_tilt_deg: PositiveFloat = 15.0

    @model_validator(mode="after")
    def _object_rests(self) -> "PickPlaceParams":
        if self.object.mass <= 0:
            raise ValueError("object.mass must be > 0 for pick-place (a static object cannot be picked)")
        return self


