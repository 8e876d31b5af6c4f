"""Episode records read back from a ``--json`` report: the typed records of a batch kind's
``episodes`` list, rebuilt from their JSON so a resumed run (``--resume``) reports them exactly as
the run that made them did.

Values are kept as JSON gave them (no coercion: an ``int`` in a ``float`` field stays an ``int``,
as it was when it was written), so writing the rebuilt records again gives the same bytes.
A value of the wrong kind raises :class:`RecordMismatch` naming where it is.
"""

from __future__ import annotations

import dataclasses
import types
import typing
from typing import Any


class RecordMismatch(ValueError):
    """A JSON value that does not fit the record type: ``where`` (``episodes[3].phases[0].name``)
    and what was expected."""

    def __init__(self, where: str, expected: str, value: object):
        self.where = where
        super().__init__(f"{where}: expected {expected}, got {type(value).__name__} {value!r:.60}")


def episode_record_type(report_type: type) -> type:
    """The record class of a report's ``episodes: list[Record]`` field."""
    hints = typing.get_type_hints(report_type)
    tp = hints.get("episodes")
    args = typing.get_args(tp)
    if typing.get_origin(tp) is not list or len(args) != 1 or not dataclasses.is_dataclass(args[0]):
        raise TypeError(f"{report_type.__name__} has no 'episodes: list[<dataclass>]' field")
    return typing.cast(type, args[0])


def records_from_json(record_type: type, data: object, where: str = "episodes") -> list[Any]:
    """A list of ``record_type`` instances from the JSON list ``data``."""
    return typing.cast(list[Any], from_json(list[record_type], data, where))  # type: ignore[valid-type]


def from_json(tp: Any, value: object, where: str) -> Any:
    """``value`` (parsed JSON) as type ``tp``: dataclasses, ``list[X]``, ``dict[str, X]``, ``X | None``,
    ``bool``, ``int``, ``float``, ``str`` and bare ``dict`` / ``Any`` (kept as they are)."""
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if tp is Any:
        return value
    if tp is dict:
        if not isinstance(value, dict):
            raise RecordMismatch(where, "an object", value)
        return value
    if origin in (typing.Union, types.UnionType):
        if value is None and type(None) in args:
            return None
        options = [a for a in args if a is not type(None)]
        for option in options:
            try:
                return from_json(option, value, where)
            except RecordMismatch:
                continue
        raise RecordMismatch(where, " or ".join(getattr(a, "__name__", str(a)) for a in args), value)
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if not isinstance(value, dict):
            raise RecordMismatch(where, f"an object ({tp.__name__})", value)
        hints = typing.get_type_hints(tp)
        fields = {f.name: f for f in dataclasses.fields(tp)}
        unknown = set(value) - set(fields)
        if unknown:
            raise RecordMismatch(f"{where}.{sorted(unknown)[0]}", f"a field of {tp.__name__}", value[sorted(unknown)[0]])
        kwargs = {}
        for name, f in fields.items():
            if name not in value:
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                    raise RecordMismatch(f"{where}.{name}", "a value (the field is missing)", None)
                continue
            kwargs[name] = from_json(hints[name], value[name], f"{where}.{name}")
        return tp(**kwargs)
    if origin is list:
        if not isinstance(value, list):
            raise RecordMismatch(where, "a list", value)
        return [from_json(args[0] if args else Any, v, f"{where}[{i}]") for i, v in enumerate(value)]
    if origin is dict:
        if not isinstance(value, dict):
            raise RecordMismatch(where, "an object", value)
        return {k: from_json(args[1] if args else Any, v, f"{where}.{k}") for k, v in value.items()}
    return _scalar(tp, value, where)


def _scalar(tp: Any, value: object, where: str) -> object:
    ok = {
        bool: isinstance(value, bool),
        int: isinstance(value, int) and not isinstance(value, bool),
        float: isinstance(value, (int, float)) and not isinstance(value, bool),
        str: isinstance(value, str),
    }.get(tp)
    if ok is None:
        raise TypeError(f"{where}: records of type {tp!r} cannot be read back from JSON")
    if not ok:
        raise RecordMismatch(where, tp.__name__, value)
    return value
