"""robocfg.config.types: pose orientation conventions; the shared field types' schemas."""

from __future__ import annotations

import json
from typing import Annotated

import numpy as np
import pytest
from pydantic import Field, TypeAdapter, ValidationError, create_model

from robocfg.config import types
from robocfg.config.types import Pose
from robocfg.geometry import euler_deg_to_quat_xyzw


def test_quaternion_orders_agree():
    q = euler_deg_to_quat_xyzw([10.0, 20.0, 30.0])
    a = Pose(quat_xyzw=list(q)).quaternion_xyzw()
    b = Pose(quat_wxyz=[q[3], q[0], q[1], q[2]]).quaternion_xyzw()
    c = Pose(euler_deg=[10.0, 20.0, 30.0]).quaternion_xyzw()
    assert np.allclose(a, b) and np.allclose(a, c)
    assert Pose().quaternion_xyzw() == (0.0, 0.0, 0.0, 1.0)


@pytest.mark.parametrize("key", ["orientation", "quat", "quaternion", "rotation"])
def test_bare_four_vector_is_rejected(key):
    with pytest.raises(ValidationError, match="ambiguous"):
        Pose.model_validate({key: [0, 0, 0, 1]})


def test_orientation_rules():
    with pytest.raises(ValidationError, match="one orientation"):
        Pose(euler_deg=[0, 0, 0], quat_xyzw=[0, 0, 0, 1])
    with pytest.raises(ValidationError, match="unit quaternion"):
        Pose(quat_wxyz=[2, 0, 0, 0])
    with pytest.raises(ValidationError):
        Pose(position=[0, 0])
    with pytest.raises(ValidationError):
        Pose(position=[0, 0, float("nan")])


# The shared field types as pydantic's own constraints spell them: CoreSchemaOf gives each of
# them the core schema pydantic derives from these (robocfg.config.types).
_FINITE = Annotated[float, Field(allow_inf_nan=False)]
_VEC3 = Annotated[list[_FINITE], Field(min_length=3, max_length=3)]
DERIVED = {
    "FiniteFloat": _FINITE,
    "Vec3": _VEC3,
    "Vec4": Annotated[list[_FINITE], Field(min_length=4, max_length=4)],
    "Matrix3": Annotated[list[_VEC3], Field(min_length=3, max_length=3)],
    "PositiveFloat": Annotated[float, Field(gt=0, allow_inf_nan=False)],
    "NonNegFloat": Annotated[float, Field(ge=0, allow_inf_nan=False)],
}
_BAD = [None, True, "1", 1, 0, -1.5, 0.0, float("inf"), float("nan"), [], [1.0], [1.0, 2.0], [1.0, 2.0, 3.0],
        [1.0, 2.0, 3.0, 4.0], [1, 2, "x"], [1.0, float("-inf"), 3.0], [[1.0, 0.0, 0.0]] * 3, [[1.0, 0.0]] * 3,
        [[1.0, 0.0, 0.0]] * 2, [[1.0, 0.0, float("nan")]] * 3, {"a": 1}, (1.0, 2.0, 3.0)]


def _without_empty_metadata(schema: object) -> object:
    if isinstance(schema, dict):
        return {k: _without_empty_metadata(v) for k, v in schema.items() if not (k == "metadata" and v == {})}
    if isinstance(schema, list):
        return [_without_empty_metadata(v) for v in schema]
    return schema


def _outcome(adapter: TypeAdapter, value: object) -> object:
    try:
        out = adapter.validate_python(value)
        return ("ok", out.model_dump() if isinstance(out, types.Frozen) else out)
    except ValidationError as exc:
        return ("error", exc.errors(include_url=False))


@pytest.mark.parametrize("name", sorted(DERIVED))
@pytest.mark.parametrize("wrap", ["plain", "optional", "list", "field"])
def test_shared_types_have_pydantics_own_schema(name: str, wrap: str) -> None:
    """Each shared type's core schema is the one pydantic derives from its constraints (but for the
    empty ``metadata`` dicts pydantic leaves in some), alone, optional, in a list and as a strict
    model's field; the JSON schemas are the same text, and every value validates or fails alike
    (the same errors, messages and locations)."""
    ours, theirs = getattr(types, name), DERIVED[name]
    if wrap == "optional":
        ours, theirs = ours | None, theirs | None
    elif wrap == "list":
        ours, theirs = list[ours], list[theirs]  # type: ignore[valid-type]
    if wrap == "field":
        a = TypeAdapter(create_model("M", __base__=types.Frozen, x=(ours, Field(description="d"))))
        b = TypeAdapter(create_model("M", __base__=types.Frozen, x=(theirs, Field(description="d"))))
        values: list[object] = [{"x": v} for v in _BAD]
        schemas = [adapter.core_schema["schema"]["fields"]["x"]["schema"] for adapter in (a, b)]  # type: ignore[index]
    else:
        a, b = TypeAdapter(ours), TypeAdapter(theirs)
        values, schemas = list(_BAD), [a.core_schema, b.core_schema]
    assert _without_empty_metadata(schemas[0]) == _without_empty_metadata(schemas[1])
    assert json.dumps(a.json_schema()) == json.dumps(b.json_schema())
    for value in values:
        assert _outcome(a, value) == _outcome(b, value), value
