"""The ``follow_target`` kind: its parameter block (``run follow-target``: the target's motion,
obstacles) and task model. Made when a task of this kind is first validated
(``robocfg.config.task.TASK_MODELS``), not in every process. Units: m, rad, s."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.task_base import TaskBase
from robocfg.config.types import (
    FiniteFloat,
    Frozen,
    NonNegFloat,
    Pose,
    PositiveFloat,
    Vec3,
    new_list,
)

MOTION_TYPES = ("static", "waypoints", "circle", "figure8")


class Motion(Frozen):
    """Target motion for follow-target (world frame, m, s).

    ``static``: stays at ``center``. ``circle``: radius ``radius`` around ``center`` in ``plane``,
    one turn per ``period``, starting at ``center + radius·(first plane axis)``. ``figure8``: a
    lemniscate of half-width ``radius`` through ``center`` in ``plane``, one loop per ``period``.
    ``waypoints``: smooth (zero velocity at each point) moves through ``waypoints`` reached at
    ``waypoint_times`` (s; default 2 s apart), then held (or repeated with ``loop``).
    """

    type: Literal["static", "waypoints", "circle", "figure8"] = "static"
    center: Vec3 = Field(default_factory=lambda: [0.5, 0.0, 0.4])
    radius: PositiveFloat = 0.1
    period: PositiveFloat = 4.0
    plane: Literal["xy", "yz", "xz"] = "yz"
    waypoints: list[Vec3] = Field(default_factory=new_list)
    waypoint_times: list[NonNegFloat] = Field(default_factory=new_list)
    loop: bool = Field(False, description="waypoints: start over after the last one.")

    @model_validator(mode="after")
    def _waypoints(self) -> "Motion":
        if self.type == "waypoints" and not self.waypoints:
            raise ValueError("motion type 'waypoints' needs a non-empty 'waypoints' list")
        if self.waypoint_times:
            if len(self.waypoint_times) != len(self.waypoints):
                raise ValueError(f"'waypoint_times' has {len(self.waypoint_times)} values for {len(self.waypoints)} waypoints")
            if any(b <= a for a, b in zip(self.waypoint_times, self.waypoint_times[1:], strict=False)):
                raise ValueError("'waypoint_times' must be strictly increasing")
        return self


class FollowObstacle(Pose):
    """An obstacle added with ``with_obstacle`` (or ``--with-obstacle``); static unless ``motion`` is given.

    ``size``: box → full extents [x, y, z]; sphere → [radius]; capsule → [radius, length] (the
    cylindrical part, along the obstacle's z). With ``motion`` the obstacle's centre follows that
    motion (same model as the target's) and ``position`` is ignored.
    """

    name: str = "obstacle"
    shape: Literal["box", "sphere", "capsule"] = "box"
    size: Annotated[list[PositiveFloat], Field(min_length=1, max_length=3)] = Field(default_factory=lambda: [0.1, 0.1, 0.1])
    color: Annotated[list[FiniteFloat], Field(min_length=4, max_length=4)] = Field(default_factory=lambda: [0.9, 0.2, 0.2, 0.8])
    motion: Motion | None = None

    @model_validator(mode="after")
    def _size_for_shape(self) -> "FollowObstacle":
        need = {"box": 3, "sphere": 1, "capsule": 2}[self.shape]
        if len(self.size) != need:
            raise ValueError(f"'size' needs {need} value(s) for shape '{self.shape}', got {len(self.size)}")
        return self


class FollowTargetParams(Frozen):
    """``run follow-target``: the TCP follows a moving target, avoiding obstacles (a QP per control step)."""

    motion: Motion = Field(default_factory=Motion)
    target_euler_deg: Vec3 = Field(default_factory=lambda: [180.0, 0.0, 0.0],
                                   description="Target orientation (deg, in orientation_frame; [180, 0, 0]: tool pointing down).")
    orientation_frame: Literal["tool", "ee_link"] = Field(
        "tool", description="Frame of target_euler_deg. " "tool (default): orientations are the tool frame's (z = approach, y = fingers' closing axis, x = y × z, defined through the robot's R_ee_graspnet), so one orientation is one physical tool pose on every robot ([180, 0, 0]: tool pointing down). ee_link: the end-effector link's own frame, as written for one robot (the meaning before this option existed; the same for robots whose R_ee_graspnet is the Panda's).")
    orientation: Literal["fixed", "following"] = Field(
        "fixed", description="fixed: target_euler_deg throughout; following: also turns about the motion plane's normal "
                             "by follow_angle_deg·sin(phase) (phase: 2π·t/period).")
    follow_angle_deg: FiniteFloat = Field(30.0, description="Amplitude of the 'following' orientation swing (deg).")
    tool_roll: Literal["auto", "tracked", "symmetric", "free"] = Field(
        "auto", description="The TCP's turn about the tool axis (ee_axis). tracked: the whole target orientation is "
                            "followed and measured. symmetric: the tool looks the same turned half a turn about its "
                            "axis (two jaws closing symmetrically), so of the target and the target turned half a turn, "
                            "the one clearly nearer (by > 10°) the arm's home orientation is tracked. free: the tool is symmetric about "
                            "its axis, so only where it points is followed and measured (orientation error = angle "
                            "between the tool axes). auto: free for a suction gripper, symmetric for a parallel "
                            "gripper, tracked otherwise (a one-jaw gripper, no gripper).")
    with_obstacle: bool = False
    obstacles: list[FollowObstacle] = Field(default_factory=new_list, description="Spawned only with with_obstacle (or --with-obstacle).")
    duration: PositiveFloat = 8.0
    control_rate: PositiveFloat = Field(240.0, description="Hz.")
    safety_margin: PositiveFloat = Field(0.02, description="m.")
    require_reach: bool = False
    settle_time: NonNegFloat = Field(1.0, description="Tracking statistics ignore the first settle_time seconds (s).")
    reach_tolerance: PositiveFloat = Field(0.005, description="Position error (m) counted as reached.")
    orientation_tolerance: PositiveFloat = Field(0.05, description="Orientation error (rad) counted as reached.")
    gain: PositiveFloat = Field(20.0, description="Cartesian servo gain (1/s); the target's velocity is fed forward too.")
    max_speed: PositiveFloat = Field(1.0, description="Cap on the commanded TCP speed (m/s).")
    acceleration: PositiveFloat = Field(10.0, description="Joint acceleration limit (rad/s²) where the robot YAML gives none.")
    velocity_scale: Annotated[float, Field(gt=0, le=1)] = Field(1.0, description="Fraction of the joint velocity limits used.")
    posture_weight: NonNegFloat = Field(1e-6, description="Weight of the pull towards the home posture (tiny: it must not fight the target).")
    self_collision: bool = Field(True, description="Also keep the robot's non-adjacent links apart.")
    escape: bool = Field(True, description="Local-minimum escape: tangent-plane via points when stalled at an obstacle.")
    placement: Literal["world", "auto"] = Field("world", description="world: the motion's points, its radius and the obstacles are world coordinates (m), used as written. auto: world coordinates written for the robot the file names; a robot that cannot reach them (--robot) gets them moved with its arm: scaled about its arm base by the ratio of the two arms' reaches towards the points (see docs/task-yaml.md).")

    @model_validator(mode="after")
    def _unique_obstacles(self) -> "FollowTargetParams":
        names = [o.name for o in self.obstacles]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"obstacle names must be unique: {dup}")
        return self


class FollowTargetTask(TaskBase):
    task: Literal["follow_target"] = Field(description="The command this file configures; selects the parameter block.")
    follow_target: FollowTargetParams = Field(default_factory=FollowTargetParams, description="Parameters of `robocfg run follow-target`.")
