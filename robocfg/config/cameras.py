"""Cameras a task declares for datasets: a fixed scene camera, a wrist camera on the EE link.

``mount: world`` — ``position`` and ``look_at`` are in the world frame (m).
``mount: ee`` — they are in the frame of the arm's ``ee_link`` (m), so the camera moves with the
wrist; ``up`` is expressed in the same frame as the other two vectors.
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.types import Frozen, PositiveFloat, Vec3


class TaskCamera(Frozen):
    """One pinhole camera rendered into every dataset frame (RGB, optionally metric depth)."""

    name: Annotated[str, Field(pattern=r"^[a-z][a-z0-9_]*$")] = Field(
        description="Key in the dataset (observation.images.<name>).")
    mount: Literal["world", "ee"] = Field("world", description="Frame of position/look_at/up: world, or the arm's ee_link.")
    position: Vec3 = Field(description="Camera centre (m), in the mount frame.")
    look_at: Vec3 = Field(description="Point the optical axis goes through (m), in the mount frame.")
    up: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 1.0], description="Image up hint, in the mount frame.")
    fov_deg: PositiveFloat = Field(60.0, description="Vertical field of view (deg).")
    width: int = Field(128, ge=16, le=1024, description="Pixels; even (video encoders need it).")
    height: int = Field(128, ge=16, le=1024, description="Pixels; even (video encoders need it).")
    near: PositiveFloat = Field(0.01, description="m.")
    far: PositiveFloat = Field(5.0, description="m.")
    depth: bool = Field(False, description="Also record metric depth along the optical axis (m).")

    @model_validator(mode="after")
    def _sane(self) -> "TaskCamera":
        if self.width % 2 or self.height % 2:
            raise ValueError(f"width and height must be even (video encoding), got {self.width}x{self.height}")
        if self.position == self.look_at:
            raise ValueError("'position' and 'look_at' must differ")
        if self.far <= self.near:
            raise ValueError("'far' must be beyond 'near'")
        return self
