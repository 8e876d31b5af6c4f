"""Parameter blocks of the ``run`` commands (one model per command). Units: m, rad, s, N."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.scene import Body
from robocfg.config.types import FiniteFloat, Frozen, NonNegFloat, Pose, PositiveFloat, Vec3


class GripperParams(Frozen):
    """``run gripper``: close then open, ``cycles`` times."""

    cycles: Annotated[int, Field(ge=1, le=100)] = 1
    mode: Literal["smooth", "direct"] = Field("smooth", description="smooth: rate-limited targets; direct: jump.")
    rate: PositiveFloat = Field(0.5, description="smooth mode: target change per second, as a fraction of the travel.")
    hold_time: PositiveFloat = Field(1.0, description="Time (s) allowed for each close or open.")
    hold_object: str | None = Field(None, description="Scene object placed between the fingers, to test holding.")
    lift_support_by: NonNegFloat = Field(0.0, description="Lower the object's support by this much (m) to test the hold.")


class Limits(Frozen):
    """Scale factors applied to the robot's velocity/acceleration/jerk limits."""

    velocity_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    acceleration_scale: Annotated[float, Field(gt=0, le=1)] = 1.0
    acceleration: PositiveFloat = Field(10.0, description="Default joint acceleration limit (rad/s²) when the robot YAML gives none.")
    jerk: PositiveFloat | None = Field(None, description="Optional jerk limit (rad/s³).")


class TrajectoryParams(Frozen):
    """``run trajectory``: time-optimal motion through joint-space or Cartesian waypoints."""

    waypoints: list[str | list[FiniteFloat] | dict[str, FiniteFloat] | Pose] = Field(
        default_factory=lambda: ["home"],
        description="'home', a list in arm-joint order (rad), a {joint: rad} map, or a Cartesian TCP pose.",
    )
    stop_at_waypoints: bool = False
    limits: Limits = Field(default_factory=Limits)
    sample_rate: PositiveFloat = Field(240.0, description="Hz.")


class Motion(Frozen):
    """Target motion for follow-target."""

    type: Literal["static", "waypoints", "circle", "figure8"] = "static"
    center: Vec3 = Field(default_factory=lambda: [0.5, 0.0, 0.4])
    radius: PositiveFloat = 0.1
    period: PositiveFloat = 4.0
    plane: Literal["xy", "yz", "xz"] = "yz"
    waypoints: list[Vec3] = Field(default_factory=list)
    waypoint_times: list[NonNegFloat] = Field(default_factory=list)


class FollowTargetParams(Frozen):
    """``run follow-target``: the TCP follows a moving target."""

    motion: Motion = Field(default_factory=Motion)
    target_euler_deg: Vec3 = Field(default_factory=lambda: [180.0, 0.0, 0.0], description="Fixed TCP orientation (deg).")
    with_obstacle: bool = False
    duration: PositiveFloat = 8.0
    control_rate: PositiveFloat = Field(240.0, description="Hz.")
    safety_margin: PositiveFloat = Field(0.02, description="m.")
    require_reach: bool = False


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
    """Per-phase time limits (s), the seed's ``events_dt`` as durations."""

    pre_grasp: PositiveFloat = 4.0
    approach: PositiveFloat = 3.0
    grasp: PositiveFloat = 1.5
    lift: PositiveFloat = 3.0
    transport: PositiveFloat = 4.0
    lower: PositiveFloat = 3.0
    release: PositiveFloat = 1.5
    retract: PositiveFloat = 3.0


class PickPlaceParams(Frozen):
    """``run pick-place``: the 8-phase pick-and-place state machine."""

    object: Body = Field(description="The object to pick (spawned resting on its support).")
    place_position: Vec3 = Field(description="Where the object's centre should end (m, world); z is ignored (it rests on the support).")
    randomize: PickPlaceRandomize = Field(default_factory=PickPlaceRandomize)
    above_height: PositiveFloat = Field(0.15, description="TCP height above the grasp point for pre-grasp/transport (m).")
    lift_height: PositiveFloat = Field(0.15, description="How far the object is lifted (m).")
    grasp_depth: FiniteFloat = Field(0.0, description="TCP height of the grasp relative to the object centre (m).")
    position_tolerance: PositiveFloat = Field(0.005, description="Phase convergence: TCP position error (m).")
    orientation_tolerance: PositiveFloat = Field(0.05, description="Phase convergence: TCP orientation error (rad).")
    timeouts: PhaseTimeouts = Field(default_factory=PhaseTimeouts)
    motion: Literal["trajectory", "reactive"] = "trajectory"
    speed_scale: Annotated[float, Field(gt=0, le=1)] = Field(0.5, description="Fraction of joint velocity limits used.")
    grip_force: PositiveFloat | None = Field(None, description="Overrides the gripper's max_force.")
    success_tolerance: PositiveFloat = Field(0.02, description="Horizontal place error allowed (m).")
    max_tilt_deg: PositiveFloat = 15.0

    @model_validator(mode="after")
    def _object_rests(self) -> PickPlaceParams:
        if self.object.mass <= 0:
            raise ValueError("object.mass must be > 0 for pick-place (a static object cannot be picked)")
        return self


class Camera(Frozen):
    """A pinhole RGB-D camera."""

    position: Vec3 = Field(default_factory=lambda: [0.5, 0.0, 0.9])
    look_at: Vec3 = Field(default_factory=lambda: [0.5, 0.0, 0.0])
    up: Vec3 = Field(default_factory=lambda: [1.0, 0.0, 0.0])
    fov_deg: PositiveFloat = 58.0
    width: int = Field(320, ge=16, le=2048)
    height: int = Field(240, ge=16, le=2048)
    near: PositiveFloat = 0.05
    far: PositiveFloat = 3.0
    depth_noise_std: NonNegFloat = Field(0.0, description="m.")


class GraspParams(Frozen):
    """``run grasp``: grasp planning from a simulated depth camera."""

    camera: Camera = Field(default_factory=Camera)
    objects: list[Body] = Field(default_factory=list)
    num_candidates: int = Field(200, ge=1)
    top_k: int = Field(10, ge=1)
    lift_height: PositiveFloat = 0.15
