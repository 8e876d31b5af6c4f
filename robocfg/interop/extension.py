"""The ``robocfg:`` block that an exported InternDataEngine file carries.

Their format has no place for what robocfg needs beyond Isaac Sim (the URDF and its
``attachments``, the gripper's closed position and finger links, drive gains, suction cups...).
``robocfg export interndata`` writes those fields, and only those, under one top-level
``robocfg:`` key with our own field names; InternDataEngine reads its keys by name and ignores it.
``robocfg import interndata`` lays the block over what it maps from their keys, so a round trip
gives back the same robot. Relative paths in the block are relative to the file that holds it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

BLOCK_KEY = "robocfg"


def rebase_path(uri: str, from_dir: Path, to_dir: Path) -> str:
    """A relative path written for ``from_dir`` rewritten for ``to_dir``; URIs and absolute paths unchanged."""
    if "://" in uri or Path(uri).expanduser().is_absolute():
        return uri
    return Path(os.path.relpath((from_dir / uri).resolve(), to_dir.resolve())).as_posix()


def rebase_paths(robot: dict[str, Any], from_dir: Path, to_dir: Path) -> dict[str, Any]:
    """A copy of a (partial) robot dict with its ``urdf``, attachment URDFs and ``package_dirs`` rebased."""
    out = dict(robot)
    if isinstance(out.get("urdf"), str):
        out["urdf"] = rebase_path(out["urdf"], from_dir, to_dir)
    if isinstance(out.get("attachments"), list):
        out["attachments"] = [
            {**a, "urdf": rebase_path(a["urdf"], from_dir, to_dir)} if isinstance(a, dict) and isinstance(a.get("urdf"), str) else a
            for a in out["attachments"]
        ]
    if isinstance(out.get("package_dirs"), dict):
        out["package_dirs"] = {k: rebase_path(v, from_dir, to_dir) if isinstance(v, str) else v
                               for k, v in out["package_dirs"].items()}
    return out


def overlay(base: Any, top: Any) -> Any:
    """``top`` laid over ``base``: mappings merge key by key, lists of equal length item by item,
    anything else (``None`` included) replaces."""
    if isinstance(base, dict) and isinstance(top, dict):
        out = dict(base)
        for k, v in top.items():
            out[k] = overlay(base[k], v) if k in base else v
        return out
    if isinstance(base, list) and isinstance(top, list) and len(base) == len(top) and all(isinstance(t, dict) for t in top):
        return [overlay(b, t) for b, t in zip(base, top, strict=True)]
    return top
