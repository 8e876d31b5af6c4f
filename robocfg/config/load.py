"""Safe YAML loading that remembers where every node came from, and pydantic errors as
``FILE:LINE:COL: path.to.field: message`` problems with "did you mean ...?" hints."""

from __future__ import annotations

import re
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, TypeAdapter, ValidationError

from robocfg.config.prescan import MAX_DEPTH, check_depth, check_size
from robocfg.errors import ConfigError, Problem
from robocfg.suggest import did_you_mean

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


# libyaml composes ~15x faster than the pure-Python parser; nodes and marks are the same.
class _FastComposer(getattr(yaml, "CSafeLoader", _Composer)):  # type: ignore[misc]
    """The composer used; its scalar resolution is extended below."""


# YAML 1.1 (PyYAML) reads ``1e-3`` as a string; numbers are validated strictly (no strings), so
# exponents without a dot must resolve as floats, as in YAML 1.2.
_EXP_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")
for _loader in {_Composer, _FastComposer}:
    _loader.add_implicit_resolver("tag:yaml.org,2002:float", _EXP_FLOAT, list("-+0123456789."))


MAX_NODES = 100_000  # after alias expansion: stops "billion laughs" documents
_MERGE_TAG = "tag:yaml.org,2002:merge"
_PLAIN_TAGS = ("tag:yaml.org,2002:map", "tag:yaml.org,2002:seq")


class _Walker:
    """Turns a composed node tree into plain data, recording the mark of every key and item.

    Rejects duplicate keys, non-scalar keys, recursive aliases, nesting deeper than
    ``MAX_DEPTH`` and documents that expand (through aliases) to more than ``MAX_NODES`` nodes.
    Supports ``<<`` merge keys (explicit keys win)."""

    def __init__(self, file: str, marks: dict):
        self.file, self.marks, self.count = file, marks, 0
        self.active: set[int] = set()
        self.constructor = _Composer("")

    def walk(self, node: yaml.Node, loc: Loc) -> Any:
        self.count += 1
        if self.count > MAX_NODES:
            raise ConfigError([_problem_at(self.file, node, loc, f"document too large: more than {MAX_NODES} nodes after expanding aliases")])
        if len(loc) > MAX_DEPTH:
            raise ConfigError([_problem_at(self.file, node, loc, f"nested more than {MAX_DEPTH} levels deep")])
        self.marks.setdefault(loc, (node.start_mark.line + 1, node.start_mark.column + 1))
        if isinstance(node, yaml.ScalarNode):
            return self.constructor.construct_object(node, deep=True)
        if node.tag not in _PLAIN_TAGS:
            raise ConfigError([_problem_at(self.file, node, loc, f"YAML error: the tag {node.tag!r} is not supported here (plain mappings and lists only)")])
        if id(node) in self.active:
            raise ConfigError([_problem_at(self.file, node, loc, "recursive alias: a node contains itself")])
        self.active.add(id(node))
        try:
            if isinstance(node, yaml.MappingNode):
                return self._mapping(node, loc)
            return [self._item(item, (*loc, i)) for i, item in enumerate(node.value)]
        finally:
            self.active.discard(id(node))

    def _item(self, node: yaml.Node, loc: Loc) -> Any:
        self.marks[loc] = (node.start_mark.line + 1, node.start_mark.column + 1)
        return self.walk(node, loc)

    def _mapping(self, node: yaml.MappingNode, loc: Loc) -> dict:
        out: dict[Any, Any] = {}
        merged: dict[Any, Any] = {}
        merged_marks: dict[Loc, tuple[int, int]] = {}
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE_TAG:
                sources = value_node.value if isinstance(value_node, yaml.SequenceNode) else [value_node]
                for src in sources:
                    if not isinstance(src, yaml.MappingNode):
                        raise ConfigError([_problem_at(self.file, src, loc, "a '<<' merge key needs a mapping (or a list of mappings)")])
                    own, self.marks = self.marks, {}
                    try:
                        values = self.walk(src, loc)
                    finally:
                        src_marks, self.marks = self.marks, own
                    for k, v in values.items():
                        merged.setdefault(k, v)
                    for m_loc, m in src_marks.items():
                        merged_marks.setdefault(m_loc, m)
                continue
            if not isinstance(key_node, yaml.ScalarNode):
                raise ConfigError([_problem_at(self.file, key_node, loc, "mapping keys must be plain scalars")])
            key = self.constructor.construct_object(key_node, deep=True)
            if key in out:
                first = self.marks.get((*loc, key), ("?", "?"))
                raise ConfigError(
                    [_problem_at(self.file, key_node, (*loc, key), f"duplicate key {key!r} (first defined at line {first[0]})")]
                )
            self.marks[(*loc, key)] = (key_node.start_mark.line + 1, key_node.start_mark.column + 1)
            out[key] = self.walk(value_node, (*loc, key))
        for k, v in merged.items():
            out.setdefault(k, v)
        for m_loc, m in merged_marks.items():
            self.marks.setdefault(m_loc, m)
        return out


def _problem_at(file: str, node: yaml.Node, loc: Loc, msg: str) -> Problem:
    return Problem(file, node.start_mark.line + 1, node.start_mark.column + 1, format_loc(loc), msg)


def load_yaml(path: str | Path) -> YamlDocument:
    """Read one YAML document safely. Raises ConfigError for I/O, syntax, duplicate keys, empty files."""
    p = Path(path)
    try:
        too_big = check_size(p.stat().st_size) if p.is_file() else None
        if too_big is not None:  # refused before reading it
            raise ConfigError([Problem(str(p), too_big.line, too_big.col, "", too_big.message)])
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError([Problem(str(p), None, None, "", "file not found")]) from None
    except UnicodeDecodeError as exc:
        raw = p.read_bytes()[: exc.start]
        line, col = raw.count(b"\n") + 1, exc.start - (raw.rfind(b"\n") + 1) + 1
        raise ConfigError([Problem(str(p), line, col, "", f"cannot read file: not UTF-8 text ({exc.reason} at byte {exc.start})")]) from None
    except OSError as exc:
        raise ConfigError([Problem(str(p), None, None, "", f"cannot read file: {exc.strerror or exc}")]) from None
    return parse_yaml(text, p)


def parse_yaml(text: str, path: Path) -> YamlDocument:
    """Parse YAML text (see :func:`load_yaml`). Size and nesting depth are checked on the text
    first: the C composer would overflow the stack on very deep nesting."""
    for limit in (check_size(len(text.encode("utf-8", "surrogatepass"))), check_depth(text)):
        if limit is not None:
            raise ConfigError([Problem(str(path), limit.line, limit.col, "", limit.message)])
    try:
        loader = _FastComposer(text)
        try:
            node = loader.get_single_node()
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        raise ConfigError([_yaml_problem(path, exc)]) from None
    except RecursionError:
        raise ConfigError([Problem(str(path), 1, 1, "", f"nested too deeply (more than {MAX_DEPTH} levels)")]) from None
    if node is None:
        raise ConfigError([Problem(str(path), 1, 1, "", "file is empty; expected a mapping")])
    marks: dict[Loc, tuple[int, int]] = {}
    try:
        data = _Walker(str(path), marks).walk(node, ())
    except yaml.YAMLError as exc:
        raise ConfigError([_yaml_problem(path, exc)]) from None
    if not isinstance(data, dict):
        kind = "a list" if isinstance(data, list) else f"a {type(data).__name__}"
        raise ConfigError([Problem(str(path), 1, 1, "", f"expected a mapping at the top level, got {kind}")])
    return YamlDocument(path, data, marks)


def _yaml_problem(path: Path, exc: yaml.YAMLError) -> Problem:
    """A YAML scanner/parser/constructor error as a problem at its mark (line 1 when unknown)."""
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, None)
        what = "YAML error" if isinstance(exc, yaml.constructor.ConstructorError) else "YAML syntax error"
        msg = f"{what}: {exc.problem or exc}"
        if exc.context:
            msg += f" ({exc.context})"
        return Problem(str(path), line, col, "", msg)
    return Problem(str(path), 1, None, "", f"YAML error: {' '.join(str(exc).split())}")


# ---------------------------------------------------------------- pydantic → problems


def validate_document(doc: YamlDocument, model: Any) -> Any:
    """Validate ``doc.data`` against a pydantic model (or annotated union). Raises ConfigError."""
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


def _message(err: dict) -> str:
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


def _get(data: Any, loc: Loc) -> Any:
    cur = data
    for part in loc:
        if (isinstance(cur, dict) and part in cur) or (isinstance(cur, list) and isinstance(part, int) and 0 <= part < len(cur)):
            cur = cur[part]
        else:
            return None
    return cur


_MISSING = object()


def _lookup(data: Any, loc: Loc) -> Any:
    """Value at ``loc`` or ``_MISSING`` (unlike :func:`_get`, tells a null from an absent key)."""
    cur = data
    for part in loc:
        if (isinstance(cur, dict) and part in cur) or (
            isinstance(cur, list) and isinstance(part, int) and not isinstance(part, bool) and 0 <= part < len(cur)
        ):
            cur = cur[part]
        else:
            return _MISSING
    return cur


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
        cur = cur[part] if isinstance(cur, (dict, list)) else None
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


def detect_kind(doc: YamlDocument) -> str:
    """'robot' or 'task' from the top-level keys."""
    if "task" in doc.data:
        return "task"
    if "arms" in doc.data or "urdf" in doc.data:
        return "robot"
    raise ConfigError([Problem(str(doc.path), 1, 1, "", "cannot tell the file kind: a robot YAML has 'urdf' and 'arms', a task YAML has 'task'")])
