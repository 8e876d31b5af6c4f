"""The ``grasp`` kind: its parameter block (``run grasp``: camera, workspace, planner) and task
model. Made when a task of this kind is first validated (``robocfg.config.task.TASK_MODELS``), not
in every process. Units: m, rad, s, N."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.commands import Region
from robocfg.config.scene import Body
from robocfg.config.task_base import TaskBase
from robocfg.config.types import (
    Frozen,
    NonNegFloat,
    PositiveFloat,
    Vec3,
    new_list,
)


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


class GraspTask(TaskBase):
    task: Literal["grasp"] = Field(description="The command this file configures; selects the parameter block.")
    grasp: GraspParams = Field(default_factory=GraspParams, description="Parameters of `robocfg run grasp`.")
