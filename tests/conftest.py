"""Suite-wide set-up: robocfg's cache folder (composed URDFs, the start-up code cache of
``robocfg.startcache``) is a temporary folder for the whole session, never the user's
``~/.cache/robocfg``; processes the tests start inherit it through the environment."""

from __future__ import annotations

import os
import shutil
import tempfile

_CACHE = "ROBOCFG_CACHE_DIR"
_saved: dict[str, str | None] = {}


def pytest_configure(config) -> None:
    _saved[_CACHE] = os.environ.get(_CACHE)
    _saved["folder"] = tempfile.mkdtemp(prefix="robocfg-test-cache-")
    os.environ[_CACHE] = _saved["folder"]


def pytest_unconfigure(config) -> None:
    folder = _saved.pop("folder", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)
    old = _saved.pop(_CACHE, None)
    if old is None:
        os.environ.pop(_CACHE, None)
    else:
        os.environ[_CACHE] = old
