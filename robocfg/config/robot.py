"""Robot YAML schema (``schema_version: 1``). One file per robot; robots are data, not classes.

Frames and conventions (see docs/robot-yaml.md): SI units; joint indices are DOF indices (the
position among the URDF's movable joints, as ``robocfg inspect`` prints them); the TCP lies at
``tcp_offset`` along ``ee_axis`` of ``ee_link``; ``R_ee_graspnet`` maps the GraspNet grasp frame
(x approach, y closing, z = x × y) to the EE frame: ``world_R_ee = world_R_grasp · R_ee_graspnet``.
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from robocfg.config.types import (
    Axis,
    FiniteFloat,
    Frozen,
    Matrix3,
    NonNegFloat,
    PositiveFloat,
    SchemaVersion,
    Vec3,
    new_list,
)
from robocfg.suggest import did_you_mean

# Names of the IK backends built into robocfg.kinematics.ik (config must not import the solvers;
# a test checks this table against the backend registry).
IK_BACKENDS = ("lm", "pink", "placo")


class ParallelGripperConfig(Frozen):
    """A parallel-jaw gripper held by friction. Mimic followers come from the URDF's ``<mimic>`` tags."""

    type: Literal["parallel"] = Field("parallel", description="Gripper kind (selects this block).")
    joints: list[str] | None = Field(None, description="Driven (leader) joint names.")
    gripper_indices: list[int] | None = Field(None, description="DOF indices of the driven joints.")
    open: list[FiniteFloat] = Field(description="Driven-joint positions when open (rad or m).")
    closed: list[FiniteFloat] = Field(description="Driven-joint positions when closed (rad or m).")
    max_width: PositiveFloat = Field(description="Finger gap when open (m).")
    min_width: NonNegFloat = Field(0.0, description="Finger gap when closed (m).")
    finger_links: list[str] = Field(
        min_length=2, max_length=2, description="The two links whose inner faces touch the object."
    )
    max_force: PositiveFloat = Field(40.0, description="Force (N) or torque (N·m) per driven joint.")
    max_velocity: PositiveFloat | None = Field(None, description="Joint speed cap while moving (rad/s or m/s).")
    state_threshold: Annotated[float, Field(gt=0, lt=1)] = Field(
        0.9,
        description="Fraction of the closed→open travel above which the state is open (1.0), else closed (-1.0); "
        "0.9 makes any grasp read as closed: the gripper counts as open only when (nearly) fully open.",
    )
    lateral_friction: PositiveFloat = Field(1.0, description="Friction coefficient given to the finger links.")
    pad_patch_radius: NonNegFloat = Field(
        0.005,
        description="Radius (m) of the contact patch a soft finger pad makes on a gripped object; gives the "
        "pads' torsional friction (2/3 · lateral_friction · radius, m), which keeps an object gripped at two "
        "points (a curved mesh) from swinging about the closing axis. 0: point contacts.",
    )

    @model_validator(mode="after")
    def _shape(self) -> "ParallelGripperConfig":
        if self.joints is None and self.gripper_indices is None:
            raise ValueError("give the driven joints by name ('joints') and/or 'gripper_indices'")
        n = len(self.joints) if self.joints is not None else len(self.gripper_indices or [])
        for key in ("open", "closed"):
            if len(getattr(self, key)) != n:
                raise ValueError(f"'{key}' needs one value per driven joint ({n})")
        if self.gripper_indices is not None and len(self.gripper_indices) != n:
            raise ValueError("'joints' and 'gripper_indices' have different lengths")
        if list(self.open) == list(self.closed):
            raise ValueError("'open' and 'closed' are the same position")
        if self.min_width >= self.max_width:
            raise ValueError(f"min_width ({self.min_width}) must be < max_width ({self.max_width})")
        return self


class OneJawGripperConfig(ParallelGripperConfig):
    """A one-jaw gripper: one driven jaw closes against a jaw fixed to the hand (Unitree Z1 style).

    Everything a parallel gripper has, with ``finger_links: [moving jaw, fixed jaw]`` and the
    closing direction (grasp y, row 1 of ``R_ee_graspnet``) pointing from the moving jaw towards the
    fixed one. The object ends up against the fixed jaw, so the grasp centre is not on the ee_axis
    line: it is mid-way between the jaw faces at the grasp width, ``fixed_jaw_face − width/2`` along
    the closing direction. ``tcp_offset`` stays the distance along ``ee_axis`` to the jaw pads.
    """

    type: Literal["one_jaw"] = Field("one_jaw", description="Gripper kind (selects this block).")  # type: ignore[assignment]
    fixed_jaw_face: FiniteFloat = Field(
        description="Signed distance (m) from the ee_axis line to the fixed jaw's inner face, along the closing "
        "direction (grasp y); robocfg validate measures it from the collision geometry.",
    )


class SuctionGripperConfig(Frozen):
    """A suction cup: attaches an object by a constraint when the cup touches it."""

    type: Literal["suction"] = Field("suction", description="Gripper kind (selects this block).")
    link: str = Field(description="The suction-cup link; the TCP (tcp_offset along ee_axis) is its cup face, the "
                      "point of its geometry furthest along ee_axis.")
    hold_force: PositiveFloat = Field(50.0, description="Largest pulling load (N) before the object lets go.")
    activation_distance: NonNegFloat = Field(0.005, description="Max gap (m) between cup and object to attach.")


GripperConfig = Annotated[ParallelGripperConfig | OneJawGripperConfig | SuctionGripperConfig, Field(discriminator="type")]


class GripperKeypoints(Frozen):
    """Points in the EE frame (m) for drawing the gripper."""

    tool_head: Vec3 = Field(description="Fingertip point (approach direction).")
    tool_tail: Vec3 = Field(description="Gripper base point.")
    tool_side: Vec3 = Field(description="A point on one side, for width display.")


class CollisionFilter(Frozen):
    """Link name lists for contact handling."""

    ignore_links: list[str] = Field(default_factory=new_list, description="Links whose contacts with the object are ignored.")
    forbid_links: list[str] = Field(default_factory=new_list, description="Arm links that must never touch anything.")


class ArmConfig(Frozen):
    """One arm: a serial chain from ``base_link`` to ``ee_link`` plus its gripper."""

    name: str = Field("arm", description="Arm name, e.g. 'left'/'right' on a dual-arm robot.")
    joints: list[str] | None = Field(None, description="Arm joint names, base to tip.")
    joint_indices: list[int] | None = Field(None, description="DOF indices of the arm joints.")
    base_link: str = Field(description="Link the arm chain starts from (the kinematic base).")
    ee_link: str = Field(description="End-effector link, rigidly attached to the last arm joint.")
    tcp_offset: PositiveFloat = Field(description="Distance (m) from the ee_link origin to the TCP along ee_axis.")
    ee_axis: Axis = Field(description="Axis of ee_link pointing from its origin to the TCP.")
    R_ee_graspnet: Matrix3 = Field(description="Rotation with world_R_ee = world_R_grasp · R_ee_graspnet.")
    home: list[FiniteFloat] = Field(description="Home joint positions (rad or m), arm-joint order.")
    home_std: list[NonNegFloat] | None = Field(None, description="Std-dev (rad) for home randomisation.")
    gripper: GripperConfig | None = Field(None, description="This arm's gripper.")
    gripper_keypoints: GripperKeypoints | None = Field(None, description="Gripper points in the ee_link frame (m), for drawing.")
    collision_filter: CollisionFilter = Field(default_factory=CollisionFilter, description="Link lists for contact handling.")

    @model_validator(mode="after")
    def _shape(self) -> "ArmConfig":
        if self.joints is None and self.joint_indices is None:
            raise ValueError("give the arm joints by name ('joints') and/or 'joint_indices'")
        n = len(self.joints) if self.joints is not None else len(self.joint_indices or [])
        if self.joint_indices is not None and len(self.joint_indices) != n:
            raise ValueError("'joints' and 'joint_indices' have different lengths")
        if len(self.home) != n:
            raise ValueError(f"'home' has {len(self.home)} values for {n} arm joints")
        if self.home_std is not None and len(self.home_std) != n:
            raise ValueError(f"'home_std' has {len(self.home_std)} values for {n} arm joints")
        return self


class DriveGains(Frozen):
    """Position-drive gains for a joint group.

    PyBullet mapping: ``positionGain = stiffness``, ``velocityGain = damping`` in
    ``setJointMotorControlArray(POSITION_CONTROL)``, which applies
    ``kp·(q* − q) + kd·(q̇* − q̇)`` as an impulse-level error term, capped at ``max_force``.
    """

    stiffness: PositiveFloat = Field(0.1, description="PyBullet positionGain (dimensionless ERP-like gain).")
    damping: PositiveFloat = Field(1.0, description="PyBullet velocityGain.")
    max_force: PositiveFloat = Field(200.0, description="Per-joint force/torque cap (N or N·m).")


class Drives(Frozen):
    """Drive settings and optional limit overrides."""

    arm: DriveGains = Field(default_factory=DriveGains, description="Position-drive gains of the arm joints.")
    velocity_limits: dict[str, PositiveFloat] = Field(default_factory=dict, description="rad/s by joint name; overrides the URDF.")
    acceleration_limits: dict[str, PositiveFloat] = Field(default_factory=dict, description="rad/s² by joint name.")


class Physics(Frozen):
    """PyBullet solver settings: solver iterations, self-collision, link-mass overrides."""

    solver_iterations: Annotated[int, Field(ge=1, le=10000)] = Field(150, description="PyBullet numSolverIterations.")
    self_collision: bool = Field(True, description="Enable self-collision (parents excluded, finger linkage filtered).")
    link_masses: dict[str, PositiveFloat] = Field(
        default_factory=dict, description="kg by link name; overrides links that lack an <inertial>."
    )


class Attachment(Frozen):
    """A URDF welded onto a link of the robot (e.g. a gripper on the arm's flange).

    robocfg composes the robot's ``urdf`` and its attachments, in order, into one URDF (cached in
    ``$XDG_CACHE_HOME/robocfg``); every link/joint name elsewhere in the robot YAML refers to that
    composed URDF. An attachment's root link becomes the child of a fixed joint
    ``{name}_mount`` on ``mount_link`` (a link of the arm or of an earlier attachment).
    """

    urdf: str = Field(description="Path relative to this YAML, or pybullet_data://, airo_models://, package://.")
    mount_link: str = Field(description="Link (of the composed URDF so far) the attachment's root link is welded to.")
    mount_xyz: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0], description="Root-link origin in the mount_link frame (m).")
    mount_rpy_deg: Vec3 = Field(
        default_factory=lambda: [0.0, 0.0, 0.0],
        description="Root-link orientation in the mount_link frame: roll, pitch, yaw (deg), R = Rz·Ry·Rx (URDF rpy).",
    )
    name: str | None = Field(
        None, pattern=r"^[A-Za-z0-9_\-]+$",
        description="Attachment name (default: the URDF file stem); prefixes clashing names and names the mount joint.",
    )
    prefix: str | None = Field(
        None, pattern=r"^[A-Za-z0-9_\-]*$",
        description="If given, prepended to *every* link/joint name of the attachment; if not, only names that clash get '{name}_'.",
    )


class RobotConfig(Frozen):
    """A robot YAML file."""

    schema_version: SchemaVersion = Field(description="File format version; this is 1.")
    name: str = Field(pattern=r"^[A-Za-z0-9_\-]+$", description="Robot name used on the command line.")
    description: str = Field("", description="Free text, shown by `robocfg robots`.")
    urdf: str = Field(description="Path relative to this YAML, or pybullet_data://, airo_models://, package://.")
    package_dirs: dict[str, str] = Field(default_factory=dict, description="package:// name → directory.")
    attachments: list[Attachment] = Field(
        default_factory=new_list, description="URDFs welded onto the robot (grippers, tools), composed into one URDF in order."
    )
    fixed_base: bool = Field(True, description="Weld the URDF root link to the world (PyBullet useFixedBase).")
    arms: list[ArmConfig] = Field(min_length=1, description="One entry per arm.")
    drives: Drives = Field(default_factory=Drives, description="Drive gains and joint-limit overrides.")
    locked_joints: dict[str, FiniteFloat] = Field(
        default_factory=dict,
        description="Joints no arm or gripper moves, held at these positions (m or rad): position-driven there "
                    "(at the URDF effort limit) in the simulation and locked there in the kinematic model, e.g. a "
                    "torso lift at its home height. Joints neither listed nor driven stay at 0 (clipped into their limits).",
    )
    physics: Physics = Field(default_factory=Physics, description="Solver settings and link-mass overrides.")
    ik_backend: str = Field("lm", description=f"Default IK backend name: {', '.join(IK_BACKENDS)}.")

    @field_validator("ik_backend")
    @classmethod
    def _known_backend(cls, v: str) -> str:
        if v not in IK_BACKENDS:
            raise ValueError(f"unknown IK backend {v!r}{did_you_mean(v, IK_BACKENDS)}; known: {', '.join(IK_BACKENDS)}")
        return v

    @model_validator(mode="after")
    def _unique_arms(self) -> "RobotConfig":
        names = [a.name for a in self.arms]
        if len(set(names)) != len(names):
            raise ValueError(f"arm names must be unique, got {names}")
        return self

    def arm(self, name: str | None = None) -> ArmConfig:
        """The named arm, or the first one."""
        if name is None:
            return self.arms[0]
        for a in self.arms:
            if a.name == name:
                return a
        from robocfg.errors import NotFound

        raise NotFound("arm", name, [a.name for a in self.arms])


class RobotSource(Frozen):
    """What ``robocfg new-robot`` drafts from when given a YAML file instead of a URDF: a robot
    composed of a URDF and its attachments (e.g. an arm and a gripper from two packages)."""

    urdf: str = Field(description="Path relative to this YAML, or pybullet_data://, airo_models://, package://.")
    package_dirs: dict[str, str] = Field(default_factory=dict, description="package:// name → directory.")
    attachments: list[Attachment] = Field(default_factory=new_list, description="URDFs welded onto the robot, in order.")
