"""Pydantic validation of a loaded YAML document, errors as ``FILE:LINE:COL: path.to.field: message``
problems with "did you mean ...?" hints (positions from :mod:`robocfg.config.load`)."""

from __future__ import annotations

import re
import typing
from collections.abc import Callable
from typing import Any

from pydantic import BaseModel, TypeAdapter, ValidationError
from pydantic_core import ErrorDetails

from robocfg.config.load import Loc, YamlDocument
from robocfg.errors import ConfigError, Problem
from robocfg.suggest import did_you_mean


def validate_document(doc: YamlDocument, model: Any) -> Any:
    """Validate ``doc.data`` against a pydantic model (or annotated union). Raises ConfigError."""
    validate: Callable[[Any], Any]
    if isinstance(model, type) and issubclass(model, BaseModel):
        validate, tp = model.model_validate, model  # builds (once) and keeps the model's validator
    else:
        adapter = model if isinstance(model, TypeAdapter) else _adapter(model)
        validate, tp = adapter.validate_python, getattr(adapter, "_type", model)
    try:
        return validate(doc.data)
    except ValidationError as exc:
        raise ConfigError(errors_to_problems(doc, exc, tp)) from None


_ADAPTERS: dict[int, TypeAdapter] = {}


def _adapter(tp: Any) -> TypeAdapter:
    """One TypeAdapter per type: building one costs ~0.1 s for the task union."""
    if id(tp) not in _ADAPTERS:
        _ADAPTERS[id(tp)] = TypeAdapter(tp)
    return _ADAPTERS[id(tp)]


def errors_to_problems(doc: YamlDocument, exc: ValidationError, model: Any) -> list[Problem]:
    problems = []
    seen: set[tuple] = set()
    for err in exc.errors(include_url=False):
        loc = _data_loc(model, doc.data, err["loc"], err["type"])
        msg = _message(err)
        if err["type"] in ("value_error", "assertion_error"):
            loc = _refine(doc.data, loc, msg)
        if err["type"] == "extra_forbidden":
            known = _fields_at(model, doc.data, loc[:-1])
            hint = did_you_mean(str(loc[-1]), known) or _other_member_hint(model, doc.data, loc[:-1], str(loc[-1]))
            msg = f"unknown key {loc[-1]!r}{hint}"
        elif err["type"] == "union_tag_invalid":
            ctx = err.get("ctx", {})
            tag, expected = ctx.get("tag"), ctx.get("expected_tags", "")
            names = [t.strip().strip("'") for t in str(expected).split(",")]
            msg = f"unknown value {tag!r}{did_you_mean(str(tag), names)}; valid: {expected}"
            key = ctx.get("discriminator", "").strip("'")
            if key and key in (_get(doc.data, loc) or {}):
                loc = (*loc, key)
        key = (loc, msg)
        if key in seen:
            continue
        seen.add(key)
        problems.append(doc.problem(loc, msg))
    return problems


def _message(err: ErrorDetails) -> str:
    msg = str(err["msg"])
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    if err["type"] == "missing":
        msg = "required field is missing"
    if err["type"] in ("float_type", "int_type", "bool_type", "string_type") and isinstance(err.get("input"), (bool, int, float, str)):
        msg = f"{msg} (got {err['input']!r})"
    if err["type"] == "literal_error" and "input" in err:
        msg = f"{msg} (got {err['input']!r})"
    return msg


_MISSING = object()


def _get(data: Any, loc: Loc) -> Any:
    """Value at ``loc``, None where there is none."""
    value = _lookup(data, loc)
    return None if value is _MISSING else value


def _lookup(data: Any, loc: Loc) -> Any:
    """Value at ``loc`` or ``_MISSING`` (unlike :func:`_get`, tells a null from an absent key)."""
    cur = data
    for part in loc:
        cur = _child(cur, part)
        if cur is _MISSING:
            break
    return cur


def _child(cur: Any, part: str | int) -> Any:
    """``cur[part]`` of a mapping holding the key or a list holding the index ``part``, else ``_MISSING``."""
    if isinstance(cur, dict):
        return cur.get(part, _MISSING)
    if isinstance(cur, list) and isinstance(part, int) and not isinstance(part, bool) and 0 <= part < len(cur):
        return cur[part]
    return _MISSING


def _data_loc(model: Any, data: Any, loc: tuple, err_type: str = "") -> Loc:
    """Turn pydantic's ``loc`` into a path through the YAML data.

    Walks the model type alongside: where the type is a union, pydantic inserts the member's
    tag or type name (``'parallel'``, ``'pick_place'``, ``'list[float]'``); that part is dropped,
    even when it happens to equal a key of the data. A key absent from the data is kept only at
    the leaf of a ``missing`` error."""
    out: list[str | int] = []
    tp, cur = model, data
    for i, part in enumerate(loc):
        members = _members(tp) if tp is not None else []
        if len(members) > 1:
            tp = _member_for(members, part)  # this part names the union member: skip it
            continue
        if _lookup(cur, (part,)) is not _MISSING:
            out.append(part)
            cur = cur[part]
            tp = _child_type(members[0], part) if members else None
        elif i == len(loc) - 1 and err_type == "missing" and isinstance(cur, dict) and isinstance(part, str):
            out.append(part)
        else:
            tp = None  # an internal part ('function-after[...]', a member name...): skip it
    return tuple(out)


def _members(tp: Any) -> list[Any]:
    """Members of a (possibly Annotated / Optional) union type, NoneType excluded."""
    return [t for t in _unwrap(tp) if t is not type(None)]


def _member_for(members: list[Any], part: Any) -> Any:
    for m in members:
        if isinstance(m, type) and issubclass(m, BaseModel):
            if m.__name__ == part:
                return m
            for name in ("task", "type"):
                f = m.model_fields.get(name)
                if f is not None and typing.get_origin(f.annotation) is typing.Literal and part in typing.get_args(f.annotation):
                    return m
    return None


def _child_type(tp: Any, part: Any) -> Any:
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        f = tp.model_fields.get(part) if isinstance(part, str) else None
        return f.annotation if f is not None else None
    origin = typing.get_origin(tp)
    if origin is list and isinstance(part, int):
        return typing.get_args(tp)[0]
    if origin is dict:
        return typing.get_args(tp)[1]
    return None


def _refine(data: Any, loc: Loc, msg: str) -> Loc:
    """A model validator's message that starts with a key path below ``loc`` ("'home' has 6
    values", "object.mass must be > 0") points at that key, so the line number is the key's."""
    m = re.match(r"^'?([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)'?", msg)
    if not m:
        return loc
    parts = tuple(m.group(1).split("."))
    return (*loc, *parts) if _lookup(data, (*loc, *parts)) is not _MISSING else loc


def _type_at(model: Any, data: Any, loc: Loc) -> Any:
    """The (unpicked) type that validates the data at ``loc``, or None."""
    tp = model
    cur = data
    for part in loc:
        tp = _pick_model(tp, cur)
        if isinstance(part, int):
            tp = _item_type(tp)
        elif isinstance(tp, type) and issubclass(tp, BaseModel) and part in tp.model_fields:
            tp = tp.model_fields[part].annotation
        else:
            return None
        cur = _get(cur, (part,))
    return tp


def _fields_at(model: Any, data: Any, loc: Loc) -> list[str]:
    """Field names of the pydantic model that validates the mapping at ``loc``."""
    tp = _pick_model(_type_at(model, data, loc), _get(data, loc))
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return list(tp.model_fields)
    return []


def _other_member_hint(model: Any, data: Any, loc: Loc, key: str) -> str:
    """For a key unknown to the chosen union member but known to others: which tag allows it."""
    members = [t for t in _members(_type_at(model, data, loc)) if isinstance(t, type) and issubclass(t, BaseModel)]
    here = _get(data, loc)
    tags = []
    for m in members:
        if key not in m.model_fields:
            continue
        for name in ("task", "type"):
            f = m.model_fields.get(name)
            if f is not None and typing.get_origin(f.annotation) is typing.Literal:
                tags += [f"{name}: {v}" for v in typing.get_args(f.annotation)]
                current = here.get(name) if isinstance(here, dict) else None
                tags[-1] += f" (this mapping has {name}: {current})" if current is not None and len(tags) == 1 else ""
    return f"; {key!r} is only valid with {' or '.join(tags)}" if tags else ""


def _unwrap(tp: Any) -> list[Any]:
    origin = typing.get_origin(tp)
    if origin is typing.Annotated:
        return _unwrap(typing.get_args(tp)[0])
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)):
        out = []
        for a in typing.get_args(tp):
            out.extend(_unwrap(a))
        return out
    return [tp]


def _item_type(tp: Any) -> Any:
    for t in _unwrap(tp):
        if typing.get_origin(t) is list:
            return typing.get_args(t)[0]
    return None


def _pick_model(tp: Any, data: Any) -> Any:
    members = [t for t in _unwrap(tp) if isinstance(t, type) and issubclass(t, BaseModel)]
    if not members:
        return tp
    if len(members) == 1 or not isinstance(data, dict):
        return members[0]
    for m in members:  # discriminated by a Literal field matching the data
        for name, f in m.model_fields.items():
            if (name in ("task", "type") and typing.get_origin(f.annotation) is typing.Literal
                    and data.get(name) in typing.get_args(f.annotation)):
                return m
    return max(members, key=lambda m: len(set(m.model_fields) & set(data)))


