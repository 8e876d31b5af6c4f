"""The ``robocfg`` command lines shown in README.md and docs/*.md, for the docs tests.

Every fenced code block is read; a line is a command when it starts with ``robocfg`` (after an
optional ``$ `` prompt), and each ``robocfg`` command of a ``&&`` / ``;`` chain counts. A block
preceded by the line ``<!-- docs-test: run -->`` is run, not only parsed: its commands in order,
in one folder, so a command may read what an earlier one wrote.
"""

from __future__ import annotations

import re
import shlex
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
RUN_MARK = "<!-- docs-test: run -->"
_FENCE = re.compile(r"^(\s*)(```+|~~~+)")


@dataclass(frozen=True)
class DocCommand:
    """One command line: where it is shown, its arguments after ``robocfg``, whether its block
    is marked to be run."""

    file: str
    line: int
    args: tuple[str, ...]
    run: bool
    block: int  # line of the opening fence

    def __str__(self) -> str:
        return f"{self.file}:{self.line}: robocfg {shlex.join(self.args)}"


def doc_commands() -> list[DocCommand]:
    out: list[DocCommand] = []
    for path in DOCS:
        out += _commands_in(path)
    return out


def _commands_in(path: Path) -> list[DocCommand]:
    lines = path.read_text().splitlines()
    out: list[DocCommand] = []
    fence, run, prev, block = None, False, "", 0
    for number, line in enumerate(lines, 1):
        m = _FENCE.match(line)
        if fence is None:
            if m:
                fence, run, block = m.group(2), prev.strip() == RUN_MARK, number
            elif line.strip():
                prev = line
            continue
        if m and m.group(2).startswith(fence[0]) and line.strip() == m.group(2):
            fence, prev = None, ""
            continue
        for args in _robocfg_calls(line):
            out.append(DocCommand(str(path.relative_to(ROOT)), number, args, run, block))
    return out


def _robocfg_calls(line: str) -> list[tuple[str, ...]]:
    text = line.strip()
    if text.startswith("$ "):
        text = text[2:]
    if not text.startswith("robocfg") and "&& robocfg" not in text:
        return []
    text = _without_substitutions(text)
    try:
        words = shlex.split(text, comments=True)
    except ValueError:  # unbalanced quotes: not a command line
        return []
    calls, current = [], None
    for w in words:
        if w in ("&&", ";", "||", "|"):
            if current is not None:
                calls.append(tuple(current))
            current = None
        elif w.endswith(";") and current is not None:
            current.append(w[:-1])
            calls.append(tuple(current))
            current = None
        elif current is not None:
            current.append(w)
        elif w == "robocfg":
            current = []
    if current is not None:
        calls.append(tuple(current))
    return calls


def _without_substitutions(text: str) -> str:
    """``$(...)`` (nested parentheses included) replaced by one word: a value the reader's shell
    computes, such as a path."""
    while "$(" in text:
        start = text.index("$(")
        depth, end = 0, len(text)
        for i in range(start + 1, len(text)):
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            if depth == 0:
                end = i + 1
                break
        text = text[:start] + "SUBST" + text[end:]
    return text
