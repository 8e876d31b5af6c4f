"""Cheap checks on YAML text before any YAML library sees it: size and nesting depth.

Why: libyaml's composer recurses once per nesting level, so a ~50 KB file of ``[[[[...`` or
``- - - - ...`` overflows the C stack (the process dies with SIGSEGV, no message), and its scanner
slows down quadratically with depth. A multi-megabyte file takes seconds to compose before any
check runs. Config files are a few KB, so both limits can be far below what hurts.

The depth scan is a line-by-line estimate: block depth from the indentation stack plus the
compact ``- `` markers that open a sequence on the same line, flow depth from ``[``/``{`` that
open a flow collection (outside quoted scalars, comments and ``|``/``>`` block scalars). It only
has to stop pathological files early; the exact depth limit is enforced again while walking
the composed nodes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

MAX_BYTES = 256 * 1024  # a robot or task YAML is a few KB; 256 KiB composes in well under a second
MAX_DEPTH = 100  # nesting levels (mappings and sequences)

_BLOCK_SCALAR = re.compile(r"(?:^|[\s:-])[|>][+-]?[0-9]?[+-]?\s*$")
# A node (quoted scalar, flow collection) may begin after one of these ("" = line start); inside
# a plain scalar such as ``x[1]`` brackets and quotes are text.
_BLOCK_OPENERS = frozenset(["", "-", ":", "?"])
_FLOW_OPENERS = frozenset(["", "-", ":", "?", ",", "[", "{"])


@dataclass(frozen=True)
class TextLimitExceeded:
    """Where the text breaks a limit: 1-based line and column, and why."""

    line: int
    col: int | None
    message: str


def check_size(n_bytes: int) -> TextLimitExceeded | None:
    """A file of ``n_bytes`` bytes is refused when larger than :data:`MAX_BYTES`."""
    if n_bytes > MAX_BYTES:
        return TextLimitExceeded(1, None, f"file is {n_bytes} bytes, more than the {MAX_BYTES // 1024} KiB "
                                          "allowed for a config file")
    return None


def check_depth(text: str, limit: int = MAX_DEPTH) -> TextLimitExceeded | None:
    """The first place where the estimated nesting depth exceeds ``limit``, or None."""
    indents: list[int] = []
    flow = 0
    quote = ""  # the open quote character of a multi-line quoted scalar
    block_scalar_indent: int | None = None
    for lineno, line in enumerate(text.splitlines(), start=1):
        stripped = line.lstrip(" ")
        indent = len(line) - len(stripped)
        if block_scalar_indent is not None:
            if not stripped.strip() or indent > block_scalar_indent:
                continue  # text of a literal/folded block scalar
            block_scalar_indent = None
        if not quote and flow == 0:
            if not stripped.strip() or stripped.startswith("#"):
                continue
            while indents and indents[-1] > indent:
                indents.pop()
            if not indents or indents[-1] < indent:
                indents.append(indent)
        depth = len(indents)
        prev = "-" if not quote and flow == 0 else ("," if flow else "")
        i, n = (indent if not quote else 0), len(line)
        while i < n:
            ch = line[i]
            if quote:
                if ch == "\\" and quote == '"':
                    i += 2
                    continue
                if ch == quote:
                    quote, prev = "", "x"
                i += 1
                continue
            if ch in " \t":
                i += 1
                continue
            if ch == "#" and (i == 0 or line[i - 1] in " \t"):
                break
            starts_node = prev in (_FLOW_OPENERS if flow else _BLOCK_OPENERS)
            if ch in "'\"" and starts_node:
                quote = ch
            elif ch in "[{" and starts_node:
                flow += 1
            elif ch in "]}" and flow:
                flow -= 1
            elif ch == "-" and not flow and prev in ("-", "") and (i + 1 == n or line[i + 1] in " \t"):
                depth += 1  # a compact nested sequence entry: "- - x"
            if depth + flow > limit:
                return TextLimitExceeded(lineno, i + 1, f"nested more than {limit} levels deep")
            prev = ch
            i += 1
        if not quote and flow == 0 and _BLOCK_SCALAR.search(line.split(" #", 1)[0]):
            block_scalar_indent = indent
    return None
