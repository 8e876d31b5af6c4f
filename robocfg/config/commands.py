"""Parameter blocks of the ``run`` commands (one model per command). Units: m, rad, s, N."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.scene import Body
from robocfg.config.types import (
    FiniteFloat,
    Frozen,
    NonNegFloat,
    Pose,
    PositiveFloat,
    Vec3,
    new_list,
)


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


Waypoint = str | list[FiniteFloat] | dict[str, FiniteFloat] | Pose


def _home_only() -> list[Waypoint]:
    return ["home"]


class TrajectoryParams(Frozen):
    """``run trajectory``: time-optimal motion through joint-space or Cartesian waypoints."""

    waypoints: list[Waypoint] = Field(
        default_factory=_home_only,
        description="'home', a list in arm-joint order (rad), a {joint: rad} map, or a Cartesian TCP pose.",
    )
    stop_at_waypoints: bool = False
    limits: Limits = Field(default_factory=Limits)
    sample_rate: PositiveFloat = Field(240.0, description="Hz.")
    arm: str | None = Field(None, description="Arm that moves (default: the robot's first arm).")
    settle_time: NonNegFloat = Field(0.25, description="Time (s) the last waypoint is held after the trajectory ends.")
    gridpoints: Annotated[int, Field(ge=10, le=5000)] | None = Field(
        None, description="toppra grid size (default: 100, or 20 per segment for long paths)."
    )
    orientation_frame: Literal["tool", "ee_link"] = Field(
        "tool", description="Frame of the Cartesian waypoints' orientations. " "tool (default): orientations are the tool frame's (z = approach, y = fingers' closing axis, x = y × z, defined through the robot's R_ee_graspnet), so one orientation is one physical tool pose on every robot ([180, 0, 0]: tool pointing down). ee_link: the end-effector link's own frame, as written for one robot (the meaning before this option existed; the same for robots whose R_ee_graspnet is the Panda's).")
    placement: Literal["world", "auto"] = Field("world", description="world: Cartesian points are world coordinates (m), used as written. auto: world coordinates written for the robot the file names; a robot that cannot reach them (--robot) gets them moved with its arm: scaled about its arm base by the ratio of the two arms' reaches towards the points (see docs/task-yaml.md).")


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


class Workspace(Frozen):
    """An axis-aligned box (world frame, m): points outside it are cropped from the cloud."""

    min: Vec3 = Field(default_factory=lambda: [0.25, -0.35, -0.01])
    max: Vec3 = Field(default_factory=lambda: [0.8, 0.35, 0.35])

    @model_validator(mode="after")
    def _ordered(self) -> "Workspace":
        if any(lo >= hi for lo, hi in zip(self.min, self.max, strict=True)):
            raise ValueError(f"workspace min {self.min} must be below max {self.max} on every axis")
        return self


class GraspParams(Frozen):
    """``run grasp``: grasp planning from a simulated depth camera.

    Episode k spawns ``objects[k % len(objects)]`` (moved by ``randomize``), takes RGB-D images
    from ``camera`` and ``extra_cameras``, plans antipodal grasps on the fused cloud and executes
    the best; on failure it re-perceives and tries the next-ranked grasp (``max_attempts`` in all).
    """

    camera: Camera = Field(default_factory=Camera)
    objects: list[Body] = Field(default_factory=new_list)
    num_candidates: int = Field(200, ge=1)
    top_k: int = Field(10, ge=1)
    lift_height: PositiveFloat = 0.15
    extra_cameras: list[Camera] = Field(default_factory=new_list, description="More views fused into the one cloud.")
    workspace: Workspace = Field(default_factory=Workspace)
    voxel_size: PositiveFloat = Field(0.004, description="Voxel grid leaf (m) for downsampling.")
    friction: PositiveFloat = Field(0.5, description="Friction coefficient assumed by the planner (friction-cone half angle atan μ).")
    pre_grasp_distance: PositiveFloat = Field(0.1, description="Pre-grasp stand-off back along the approach (m).")
    randomize: Region = Field(default_factory=lambda: Region(xy_range=[0.08, 0.08], yaw_range_deg=180.0))
    max_attempts: int = Field(3, ge=1, description="Grasp attempts per episode (re-perceiving after each failure).")
    shake: bool = Field(True, description="After the lift, shake the object (±shake_amplitude along y, twice).")
    shake_amplitude: PositiveFloat = Field(0.04, description="m.")
    speed_scale: Annotated[float, Field(gt=0, le=1)] = Field(0.5, description="Fraction of joint velocity limits used.")
    grip_force: PositiveFloat | None = Field(None, description="Overrides the gripper's max_force.")
    position_tolerance: PositiveFloat = Field(0.005, description="Phase convergence: EE position error (m).")
    orientation_tolerance: PositiveFloat = Field(0.05, description="Phase convergence: EE orientation error (rad).")
    phase_timeout: PositiveFloat = Field(4.0, description="Time limit (s) of each motion phase.")
    min_object_points: int = Field(30, ge=1, description="Fewer object points in the workspace → the run fails.")
