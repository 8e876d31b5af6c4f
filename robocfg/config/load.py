"""Safe YAML loading that remembers where every node came from, and pydantic errors as
``FILE:LINE:COL: path.to.field: message`` problems with "did you mean ...?" hints."""

from __future__ import annotations

import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, TypeAdapter, ValidationError

from robocfg.config.suggest import did_you_mean
from robocfg.errors import ConfigError, Problem

Loc = tuple[str | int, ...]
M = TypeVar("M")


@dataclass
class YamlDocument:
    """Plain data plus the (line, col) — 1-based — of every mapping key / sequence item."""

    path: Path
    data: Any
    marks: dict[Loc, tuple[int, int]] = field(default_factory=dict)

    def mark(self, loc: Loc) -> tuple[int, int] | None:
        """Mark of the deepest existing prefix of ``loc``."""
        for n in range(len(loc), -1, -1):
            m = self.marks.get(tuple(loc[:n]))
            if m is not None:
                return m
        return None

    def problem(self, loc: Loc, message: str, severity: str = "error") -> Problem:
        mark = self.mark(loc)
        line, col = mark if mark else (None, None)
        return Problem(str(self.path), line, col, format_loc(loc), message, severity)  # type: ignore[arg-type]


def format_loc(loc: Loc) -> str:
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


class _Composer(yaml.SafeLoader):
    """SafeLoader whose composed node tree we walk ourselves."""


def _walk(node: yaml.Node, loc: Loc, marks: dict, file: str) -> Any:
    marks.setdefault(loc, (node.start_mark.line + 1, node.start_mark.column + 1))
    if isinstance(node, yaml.MappingNode):
        out: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                raise ConfigError([_problem_at(file, key_node, loc, "mapping keys must be plain scalars")])
            key = _scalar(key_node)
            if key in out:
                first = marks.get((*loc, key), ("?", "?"))
                raise ConfigError(
                    [_problem_at(file, key_node, (*loc, key), f"duplicate key {key!r} (first defined at line {first[0]})")]
                )
            marks[(*loc, key)] = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
            out[key] = _walk(value_node, (*loc, key), marks, file)
        return out
    if isinstance(node, yaml.SequenceNode):
        items = []
        for i, item in enumerate(node.value):
            marks[(*loc, i)] = (item.start_mark.line + 1, item.start_mark.column + 1)
            items.append(_walk(item, (*loc, i), marks, file))
        return items
    return _scalar(node)


def _scalar(node: yaml.Node) -> Any:
    loader = _Composer("")
    return loader.construct_object(node, deep=True)


def _problem_at(file: str, node: yaml.Node, loc: Loc, msg: str) -> Problem:
    return Problem(file, node.start_mark.line + 1, node.start_mark.column + 1, format_loc(loc), msg)


def load_yaml(path: str | Path) -> YamlDocument:
    """Read one YAML document safely. Raises ConfigError for I/O, syntax, duplicate keys, empty files."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError([Problem(str(p), None, None, "", "file not found")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError([Problem(str(p), None, None, "", f"cannot read file: {exc}")]) from None
    return parse_yaml(text, p)


def parse_yaml(text: str, path: Path) -> YamlDocument:
    """Parse YAML text (see :func:`load_yaml`)."""
    try:
        loader = _Composer(text)
        try:
            node = loader.get_single_node()
        finally:
            loader.dispose()
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (None, None)
        msg = f"YAML syntax error: {exc.problem or exc}"
        if exc.context:
            msg += f" ({exc.context})"
        raise ConfigError([Problem(str(path), line, col, "", msg)]) from None
    except yaml.YAMLError as exc:
        raise ConfigError([Problem(str(path), None, None, "", f"YAML error: {exc}")]) from None
    if node is None:
        raise ConfigError([Problem(str(path), 1, 1, "", "file is empty; expected a mapping")])
    marks: dict[Loc, tuple[int, int]] = {}
    try:
        data = _walk(node, (), marks, str(path))
    except yaml.YAMLError as exc:
        raise ConfigError([Problem(str(path), None, None, "", f"YAML error: {exc}")]) from None
    if not isinstance(data, dict):
        kind = "a list" if isinstance(data, list) else f"a {type(data).__name__}"
        raise ConfigError([Problem(str(path), 1, 1, "", f"expected a mapping at the top level, got {kind}")])
    return YamlDocument(path, data, marks)


# ---------------------------------------------------------------- pydantic → problems


def validate_document(doc: YamlDocument, model: Any) -> Any:
    """Validate ``doc.data`` against a pydantic model (or annotated union). Raises ConfigError."""
    adapter = model if isinstance(model, TypeAdapter) else TypeAdapter(model)
    try:
        return adapter.validate_python(doc.data)
    except ValidationError as exc:
        raise ConfigError(errors_to_problems(doc, exc, model)) from None


def errors_to_problems(doc: YamlDocument, exc: ValidationError, model: Any) -> list[Problem]:
    problems = []
    seen: set[tuple] = set()
    for err in exc.errors(include_url=False):
        loc = _data_loc(doc.data, err["loc"])
        msg = _message(err)
        if err["type"] == "extra_forbidden":
            known = _fields_at(model, doc.data, loc[:-1])
            msg = f"unknown key {loc[-1]!r}{did_you_mean(str(loc[-1]), known)}"
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


def _message(err: dict) -> str:
    msg = str(err["msg"])
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, ") :]
    if err["type"] == "missing":
        msg = "required field is missing"
    if err["type"] == "literal_error" and "input" in err:
        msg = f"{msg} (got {err['input']!r})"
    return msg


def _get(data: Any, loc: Loc) -> Any:
    cur = data
    for part in loc:
        if (isinstance(cur, dict) and part in cur) or (isinstance(cur, list) and isinstance(part, int) and 0 <= part < len(cur)):
            cur = cur[part]
        else:
            return None
    return cur


def _data_loc(data: Any, loc: tuple) -> Loc:
    """Drop pydantic's union-tag / function-wrapper parts so the loc follows the YAML data."""
    out: list[str | int] = []
    cur = data
    for i, part in enumerate(loc):
        if (isinstance(cur, dict) and part in cur) or (isinstance(cur, list) and isinstance(part, int) and 0 <= part < len(cur)):
            out.append(part)
            cur = cur[part]
        elif i == len(loc) - 1 and isinstance(cur, dict) and isinstance(part, str) and not _looks_internal(part):
            out.append(part)  # a missing or unknown key at the leaf
        # else: an internal part (union member name, 'function-after[...]', ...) is skipped
    return tuple(out)


def _looks_internal(part: str) -> bool:
    return "[" in part or part in {"list", "dict", "str", "int", "float"}


def _fields_at(model: Any, data: Any, loc: Loc) -> list[str]:
    """Field names of the pydantic model that validates the mapping at ``loc``."""
    tp = model
    cur = data
    for part in loc:
        tp = _pick_model(tp, cur)
        if isinstance(part, int):
            tp = _item_type(tp)
        elif isinstance(tp, type) and issubclass(tp, BaseModel) and part in tp.model_fields:
            tp = tp.model_fields[part].annotation
        else:
            return []
        cur = cur[part] if isinstance(cur, (dict, list)) else None
    tp = _pick_model(tp, cur)
    if isinstance(tp, type) and issubclass(tp, BaseModel):
        return list(tp.model_fields)
    return []


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


def detect_kind(doc: YamlDocument) -> str:
    """'robot' or 'task' from the top-level keys."""
    if "task" in doc.data:
        return "task"
    if "arms" in doc.data or "urdf" in doc.data:
        return "robot"
    raise ConfigError([Problem(str(doc.path), 1, 1, "", "cannot tell the file kind: a robot YAML has 'urdf' and 'arms', a task YAML has 'task'")])
