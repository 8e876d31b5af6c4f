"""Shared field types: vectors, rotations, poses. Units are SI; angles in degrees only in ``*_deg`` keys."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator
from pydantic_core import CoreSchema, core_schema

if TYPE_CHECKING:
    from pydantic import GetCoreSchemaHandler

from robocfg.config.pydantic_plugins import skip_empty_plugin_scan

skip_empty_plugin_scan()  # before the first validator is built (pydantic's plugin scan: robocfg.config.pydantic_plugins)

Axis = Literal["x", "y", "z"]
AXIS_INDEX: dict[str, int] = {"x": 0, "y": 1, "z": 2}


class CoreSchemaOf:
    """``Annotated`` metadata that gives a field type's pydantic-core schema built directly by
    ``build`` (a new one at each use), instead of pydantic deriving it from ``Field`` constraints.

    The shared types below occur about 80 times in the models a pick-place task and its robot
    validate with; deriving ``Vec3``'s schema from ``Annotated[list[Annotated[float,
    Field(allow_inf_nan=False)]], Field(min_length=3, max_length=3)]`` at each use cost ≈ 0.1 ms
    of the first validation (≈ 17 M instructions of a pick-place process's start in all). Each
    schema here is the one pydantic derives from the constraints in the comment beside the type
    (the same keys and values; pydantic also leaves an empty ``metadata`` dict in some of them,
    which neither validation nor the JSON schema reads), so validation, error messages and JSON
    schemas are unchanged: ``tests/test_config_types.py`` compares each with pydantic's own.
    """

    __slots__ = ("build", "name")

    def __init__(self, name: str, build: Callable[[], CoreSchema]) -> None:
        self.name, self.build = name, build

    def __get_pydantic_core_schema__(self, source: object, handler: "GetCoreSchemaHandler") -> CoreSchema:
        return self.build()

    def __repr__(self) -> str:
        return f"CoreSchemaOf({self.name})"


def _finite() -> CoreSchema:
    return core_schema.float_schema(allow_inf_nan=False)


def _vector(n: int) -> Callable[[], CoreSchema]:
    return lambda: core_schema.list_schema(_finite(), min_length=n, max_length=n)


# pydantic's spelling of each (tests/test_config_types.py): Annotated[float, Field(allow_inf_nan=False)]
FiniteFloat = Annotated[float, CoreSchemaOf("FiniteFloat", _finite)]


def _not_bool(v: object) -> object:
    if isinstance(v, bool):  # True == 1, so Literal[1] alone would take it
        raise ValueError(f"expected the number 1, got {v!r}")
    return v


SchemaVersion = Annotated[Literal[1], BeforeValidator(_not_bool)]
# Annotated[list[FiniteFloat], Field(min_length=3, max_length=3)], and 4 for Vec4
Vec3 = Annotated[list[float], CoreSchemaOf("Vec3", _vector(3))]
Vec4 = Annotated[list[float], CoreSchemaOf("Vec4", _vector(4))]
# Annotated[list[Vec3], Field(min_length=3, max_length=3)]
Matrix3 = Annotated[list[list[float]], CoreSchemaOf(
    "Matrix3", lambda: core_schema.list_schema(_vector(3)(), min_length=3, max_length=3))]
# Annotated[float, Field(gt=0, allow_inf_nan=False)] and Annotated[float, Field(ge=0, allow_inf_nan=False)]
PositiveFloat = Annotated[float, CoreSchemaOf("PositiveFloat", lambda: core_schema.float_schema(allow_inf_nan=False, gt=0))]
NonNegFloat = Annotated[float, CoreSchemaOf("NonNegFloat", lambda: core_schema.float_schema(allow_inf_nan=False, ge=0))]


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

