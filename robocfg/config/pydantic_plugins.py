"""Spare pydantic's plugin scan when no installed distribution declares a pydantic plugin.

Before building its first validator, pydantic looks for plugins: ``importlib.metadata.entry_points
(group="pydantic")`` reads the metadata of every installed distribution (0.009–0.011 s of CPU with
the ~140 distributions of a robocfg environment, in every fresh process; the scan below takes
0.002–0.003 s), then caches the answer in ``pydantic.plugin._loader._plugins``. Setting
``PYDANTIC_DISABLE_PLUGINS`` would skip it by turning off a user's plugins too; instead
:func:`skip_empty_plugin_scan` lists the same distributions (the ``*.dist-info`` and ``*.egg-info``
folders on ``sys.path``, as importlib.metadata finds them) and reads only their ``entry_points.txt``
files: when none declares the ``pydantic`` group, it fills pydantic's cache with the answer its own
scan would give (no plugins). Anything it cannot answer as cheaply (a zip archive on ``sys.path``,
another finder that lists distributions, an unreadable file, a pydantic without that cache) leaves
pydantic to scan as usual; so does any declared plugin, which pydantic then loads itself. Importing
pydantic's loader (and so ``importlib.metadata``, ≈ 0.03 s) is not spared: pydantic imports it
before its first validator whatever the cache holds.
"""

from __future__ import annotations

import os
import sys

GROUP = "pydantic"  # pydantic.plugin._loader.PYDANTIC_ENTRY_POINT_GROUP
_SKIPPED = (FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError)  # importlib.metadata's


def declares_plugins() -> bool | None:
    """Whether an installed distribution declares an entry point in the ``pydantic`` group: True,
    False, or None when this cheap scan cannot tell (then ask ``importlib.metadata``)."""
    from importlib.machinery import PathFinder

    if any(hasattr(f, "find_distributions") and f is not PathFinder for f in sys.meta_path):
        return None  # another finder lists distributions: only importlib.metadata knows them
    for entry in sys.path:
        root = os.fspath(entry) or "."
        try:
            names = os.listdir(root)
        except OSError:
            if os.path.isfile(root):
                return None  # a zip archive (importlib.metadata reads distributions inside it)
            continue  # missing, or not a folder: importlib.metadata finds nothing there either
        egg = os.path.basename(root).lower().endswith(".egg")
        for name in names:
            low = name.lower()
            if not (low.endswith((".dist-info", ".egg-info")) or (egg and low == "egg-info")):
                continue
            try:
                with open(os.path.join(root, name, "entry_points.txt"), encoding="utf-8") as f:
                    text = f.read()
            except _SKIPPED:
                continue
            except (OSError, ValueError):
                return None
            if GROUP in _sections(text):
                return True
    return False


def _sections(text: str) -> set[str]:
    """The group names of an ``entry_points.txt`` (parsed as ``importlib.metadata.Sectioned``)."""
    out = set()
    for line in text.splitlines():
        value = line.strip()
        if value.startswith("[") and value.endswith("]"):
            out.add(value.strip("[]").strip())
    return out


def skip_empty_plugin_scan() -> bool:
    """Fill pydantic's plugin cache with "no plugins" when :func:`declares_plugins` is sure there
    are none and pydantic has not looked yet; True when it did. ``PYDANTIC_DISABLE_PLUGINS`` set:
    nothing to do (pydantic reads it itself)."""
    if os.environ.get("PYDANTIC_DISABLE_PLUGINS") is not None:
        return False
    try:
        from pydantic.plugin import _loader
    except ImportError:
        return False
    if getattr(_loader, "_plugins", ()) is not None or getattr(_loader, "_loading_plugins", True) is not False:
        return False  # pydantic already looked (or is looking), or keeps its cache elsewhere
    if declares_plugins() is not False:
        return False
    _loader._plugins = {}
    return True
