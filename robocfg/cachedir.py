"""robocfg's cache folder: where composed URDFs (:mod:`robocfg.assets.compose`) and the start-up
code cache (:mod:`robocfg.startcache`) are written, never next to the user's files."""

from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """``$ROBOCFG_CACHE_DIR``, else ``$XDG_CACHE_HOME/robocfg``, else ``~/.cache/robocfg``."""
    env = os.environ.get("ROBOCFG_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg).expanduser() if xdg else Path.home() / ".cache") / "robocfg"
