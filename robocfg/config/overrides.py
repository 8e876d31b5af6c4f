"""Dotted-key overrides of a loaded YAML document (``pick_place.timeouts.grasp = 3.0``).

Overrides edit the document's plain data, so the result is validated exactly like a file; a
problem inside an overridden value is reported against the override (``override
pick_place.lift_height``), not against the file line it replaced. Pure data: no simulation imports.
The Python API's ``with_overrides`` and a command line ``--set key=value`` both come here.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from robocfg.config.load import Loc, YamlDocument, format_loc, parse_yaml
from robocfg.errors import ConfigError, Problem
from robocfg.suggest import did_you_mean

OVERRIDE_SOURCE = "override"  # the "file" an override's problems are reported against
ROBOT_OVERRIDE_SOURCE = "robot override"  # ... and a replaced first robot's (``robot=``, ``--robot``)


def parse_key(key: str) -> Loc:
    """``"robots.0.position"`` or ``"robots[0].position"`` → ``("robots", 0, "position")``."""
    parts: list[str | int] = []
    for raw in key.replace("[", ".").replace("]", "").split("."):
        if raw == "":
            raise ConfigError([Problem(OVERRIDE_SOURCE, None, None, key, "empty part in a dotted key")])
        parts.append(int(raw) if raw.lstrip("-").isdigit() else raw)
    return tuple(parts)


def parse_assignments(items: Iterable[str]) -> dict[str, Any]:
    """``["pick_place.lift_height=0.2", "robots.0.position=[0.1, 0, 0]"]`` → ``{key: value}``.

    The value is read as a YAML value by the same reader as the files (``0.2`` and ``1e-3`` are
    numbers, ``[0.1, 0, 0]`` a list, ``true`` a boolean, ``panda`` a string), so a value typed on a
    command line is validated exactly like the same text in a file. A later item with the same
    key wins. Raises ConfigError naming the item when it has no ``=`` or its value is no YAML."""
    out: dict[str, Any] = {}
    problems: list[Problem] = []
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep or not key:
            problems.append(Problem(OVERRIDE_SOURCE, None, None, item, "expected KEY=VALUE, e.g. pick_place.lift_height=0.2"))
            continue
        try:
            parse_key(key)
        except ConfigError as exc:
            problems += exc.problems
            continue
        try:
            out[key] = parse_yaml(f"value: {text.strip() or 'null'}\n", Path(key)).data["value"]
        except ConfigError as exc:
            problems.append(Problem(OVERRIDE_SOURCE, None, None, key, f"value {text!r} is not a YAML value: "
                                    f"{exc.problems[0].message}"))
    if problems:
        raise ConfigError(problems)
    return out


def apply_overrides(doc: YamlDocument, overrides: Mapping[str, Any]) -> YamlDocument:
    """A new document with each ``key → value`` set (the original is not changed).

    Intermediate mappings that the file leaves out are created (their defaults then apply);
    list items must exist. A key through a non-mapping, or a list index out of range, raises
    ConfigError naming the key. Unknown field names are left for validation to report (with a
    did-you-mean), like an unknown key in the file."""
    data = copy.deepcopy(doc.data)
    problems: list[Problem] = []
    for key, value in overrides.items():
        loc = parse_key(key)
        try:
            data = _set(data, loc, copy.deepcopy(value))
        except _BadPath as exc:
            problems.append(Problem(OVERRIDE_SOURCE, None, None, key, str(exc)))
    if problems:
        raise ConfigError(problems)
    marks = {k: v for k, v in doc.marks.items() if not any(_under(k, parse_key(o)) for o in overrides)}
    return YamlDocument(doc.path, data, marks)


def blame_overrides(exc: ConfigError, overrides: Mapping[str, Any]) -> ConfigError:
    """Re-attribute problems located inside an overridden value to the override itself."""
    keys = {format_loc(parse_key(k)): k for k in overrides}
    out = []
    for prob in exc.problems:
        hit = next((k for f, k in keys.items() if prob.path == f or prob.path.startswith((f + ".", f + "["))), None)
        out.append(replace(prob, file=OVERRIDE_SOURCE, line=None, col=None, path=hit) if hit else prob)
    return ConfigError(out)


class _BadPath(Exception):
    pass


def _under(loc: Loc, prefix: Loc) -> bool:
    return loc[: len(prefix)] == prefix


def _set(node: Any, loc: Loc, value: Any) -> Any:
    if not loc:
        return value
    head, rest = loc[0], loc[1:]
    if isinstance(node, list):
        if not isinstance(head, int) or not -len(node) <= head < len(node):
            raise _BadPath(f"no item {head!r} in a list of {len(node)}")
        node[head] = _set(node[head], rest, value)
        return node
    if node is None:
        node = {}
    if not isinstance(node, dict):
        raise _BadPath(f"cannot set {head!r} inside a {type(node).__name__} value")
    if isinstance(head, int):
        raise _BadPath(f"{head} is a list index but the value here is a mapping "
                       f"(keys: {', '.join(map(str, node)) or 'none'}){did_you_mean(str(head), list(map(str, node)))}")
    node[head] = _set(node.get(head), rest, value)
    return node
