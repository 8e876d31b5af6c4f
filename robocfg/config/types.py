"""Shared field types: vectors, rotations, poses. Units are SI; angles in degrees only in ``*_deg`` keys."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

import math
from typing import Annotated, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator

from robocfg.config.pydantic_plugins import skip_empty_plugin_scan

skip_empty_plugin_scan()  # before the first validator is built (pydantic's plugin scan: robocfg.config.pydantic_plugins)

Axis = Literal["x", "y", "z"]
AXIS_INDEX: dict[str, int] = {"x": 0, "y": 1, "z": 2}

FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]


def _not_bool(v: object) -> object:
    if isinstance(v, bool):  # True == 1, so Literal[1] alone would take it
        raise ValueError(f"expected the number 1, got {v!r}")
    return v


SchemaVersion = Annotated[Literal[1], BeforeValidator(_not_bool)]
Vec3 = Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)]
Vec4 = Annotated[list[FiniteFloat], Field(min_length=4, max_length=4)]
Matrix3 = Annotated[list[Vec3], Field(min_length=3, max_length=3)]
PositiveFloat = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegFloat = Annotated[float, Field(ge=0, allow_inf_nan=False)]


def new_list() -> list:
    """``default_factory`` of the config models' list fields: an empty list, as ``list`` gives.
    A Python function rather than the builtin ``list``: pydantic reads the signature of each
    factory as it builds a validator, and a builtin's signature is parsed from its text with
    ``tokenize``, whose first use compiles its regular expressions (≈ 5 ms of CPU in every process
    that validates a task)."""
    return []


class Frozen(BaseModel):
    """Base for every config model: immutable, unknown keys rejected."""

    # defer_build: validators are built on first use, not at import (-0.1 s on `robocfg validate`).
    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=False, defer_build=True, strict=True)


class Pose(Frozen):
    """A rigid pose: ``position`` (m, world frame) and at most one orientation key.

    Orientation keys name their convention: ``euler_deg`` (roll, pitch, yaw in degrees,
    extrinsic X-Y-Z, i.e. R = Rz(yaw)·Ry(pitch)·Rx(roll)), ``quat_xyzw`` or ``quat_wxyz``.
    A bare ``orientation``/``quat`` 4-vector is rejected because its order is ambiguous.
    """

    position: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0], description="Position (m).")
    euler_deg: Vec3 | None = Field(None, description="Roll, pitch, yaw (deg), R = Rz·Ry·Rx.")
    quat_xyzw: Vec4 | None = Field(None, description="Unit quaternion, x y z w order.")
    quat_wxyz: Vec4 | None = Field(None, description="Unit quaternion, w x y z order.")

    @model_validator(mode="before")
    @classmethod
    def _reject_bare_quaternion(cls, data: object) -> object:
        if isinstance(data, dict):
            for key in ("orientation", "quat", "quaternion", "rotation"):
                if key in data:
                    raise ValueError(
                        f"'{key}' is ambiguous: write 'euler_deg: [r, p, y]', "
                        "'quat_xyzw: [x, y, z, w]' or 'quat_wxyz: [w, x, y, z]'"
                    )
        return data

    @model_validator(mode="after")
    def _one_orientation(self) -> "Pose":
        given = [k for k in ("euler_deg", "quat_xyzw", "quat_wxyz") if getattr(self, k) is not None]
        if len(given) > 1:
            raise ValueError(f"give one orientation, not {' and '.join(given)}")
        for key in ("quat_xyzw", "quat_wxyz"):
            q = getattr(self, key)
            if q is not None and abs(math.sqrt(sum(v * v for v in q)) - 1.0) > 1e-3:
                raise ValueError(f"{key} must be a unit quaternion (norm is {math.sqrt(sum(v * v for v in q)):.4f})")
        return self

    def quaternion_xyzw(self) -> tuple[float, float, float, float]:
        """Orientation as a unit quaternion (x, y, z, w)."""
        if self.quat_xyzw is not None:
            x, y, z, w = self.quat_xyzw
        elif self.quat_wxyz is not None:
            w, x, y, z = self.quat_wxyz
        elif self.euler_deg is not None:
            # Imported here: scipy is not needed (nor loaded) by `robocfg validate`.
            from robocfg.geometry import euler_deg_to_quat_xyzw

            return euler_deg_to_quat_xyzw(self.euler_deg)
        else:
            return (0.0, 0.0, 0.0, 1.0)
        n = math.sqrt(x * x + y * y + z * z + w * w)
        return (x / n, y / n, z / n, w / n)

