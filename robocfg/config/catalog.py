"""Finding robot and task YAMLs by name on the search path: ``./robots`` (``./tasks``),
each directory in ``$ROBOCFG_PATH`` (``os.pathsep``-separated; a directory may hold the YAMLs
directly or ``robots/`` and ``tasks/`` subfolders), then the built-ins shipped in the package."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Literal

from robocfg.errors import NotFound

Kind = Literal["robots", "tasks"]
BUILTIN_DIR = Path(__file__).resolve().parent.parent / "data"


def search_dirs(kind: Kind) -> list[Path]:
    """Directories searched for ``kind``, highest priority first."""
    dirs = [Path.cwd() / kind]
    for entry in filter(None, os.environ.get("ROBOCFG_PATH", "").split(os.pathsep)):
        d = Path(entry).expanduser()
        dirs += [d / kind, d]
    dirs.append(BUILTIN_DIR / kind)
    out, seen = [], set()
    for d in dirs:
        key = d.resolve() if d.exists() else d
        if key not in seen and d.is_dir():
            seen.add(key)
            out.append(d)
    return out


def available(kind: Kind) -> dict[str, Path]:
    """name → file, the first hit on the search path winning."""
    found: dict[str, Path] = {}
    for d in search_dirs(kind):
        for f in sorted(d.glob("*.yaml")):
            found.setdefault(f.stem, f)
    return found


def find(kind: Kind, name_or_path: str) -> Path:
    """A YAML file by path (if it exists) or by name on the search path."""
    p = Path(name_or_path).expanduser()
    if p.suffix in (".yaml", ".yml") or os.sep in name_or_path:
        if p.is_file():
            return p
        if p.suffix in (".yaml", ".yml") and p.parent == Path("."):
            hit = available(kind).get(p.stem)
            if hit:
                return hit
        raise NotFound(f"{kind[:-1]} file", name_or_path, [str(f) for f in available(kind).values()])
    found = available(kind)
    if name_or_path in found:
        return found[name_or_path]
    alias = name_or_path.replace("-", "_")
    if alias in found:
        return found[alias]
    raise NotFound(kind[:-1], name_or_path, list(found))
