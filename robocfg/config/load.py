"""Safe YAML loading that remembers where every node came from (``FILE:LINE:COL`` for any value).

Validating a loaded document against the pydantic models, with errors as problems at those
positions, is :mod:`robocfg.config.validation`."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import yaml

from robocfg.config.prescan import MAX_DEPTH, check_depth, check_size
from robocfg.errors import ConfigError, Problem, Severity

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

    def problem(self, loc: Loc, message: str, severity: Severity = "error") -> Problem:
        mark = self.mark(loc)
        line, col = mark if mark else (None, None)
        return Problem(str(self.path), line, col, format_loc(loc), message, severity)


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
_LOADERS: tuple[type[yaml.resolver.BaseResolver], ...] = (_Composer, _FastComposer)
for _loader in _LOADERS:
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


def detect_kind(doc: YamlDocument) -> str:
    """'robot' or 'task' from the top-level keys."""
    if "task" in doc.data:
        return "task"
    if "arms" in doc.data or "urdf" in doc.data:
        return "robot"
    raise ConfigError([Problem(str(doc.path), 1, 1, "", "cannot tell the file kind: a robot YAML has 'urdf' and 'arms', a task YAML has 'task'")])
