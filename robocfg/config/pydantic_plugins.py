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
pydantic to scan as usual; so does any declared plugin, which pydantic then loads itself.

Importing pydantic's loader imported ``importlib.metadata`` (with ``email``, ``zipfile``, ``csv``,
``socket`` and more: ≈ 58 M instructions, ≈ 0.02 s of CPU on the 2-core laptop) for the one name
it binds, ``entry_points``, which the loader calls only to scan (never once its cache is filled).
:func:`skip_empty_plugin_scan` therefore imports pydantic's loader itself, before pydantic does,
with ``importlib.metadata`` standing in as a module whose ``entry_points`` imports the real module
at its first call and calls its ``entry_points`` (any other name the loader takes from it is the
real module's, imported then): the loader's own code, from its own bytecode, with one import
deferred. Nothing else in a robocfg process before its first episode imports
``importlib.metadata``; where something did already, or the loader is already imported, the loader
is imported (or kept) as it is.
"""

from __future__ import annotations

import builtins
import contextlib
import importlib
import os
import sys
from collections.abc import Iterator, Mapping, Sequence
from importlib.machinery import ModuleSpec, PathFinder
from types import ModuleType
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from importlib.abc import Loader  # importlib.abc imports importlib.resources: ≈ 10 ms

GROUP = "pydantic"  # pydantic.plugin._loader.PYDANTIC_ENTRY_POINT_GROUP
LOADER = "pydantic.plugin._loader"  # the module of pydantic's plugin cache
METADATA = "importlib.metadata"
_SKIPPED = (FileNotFoundError, IsADirectoryError, NotADirectoryError, PermissionError)  # importlib.metadata's


def declares_plugins() -> bool | None:
    """Whether an installed distribution declares an entry point in the ``pydantic`` group: True,
    False, or None when this cheap scan cannot tell (then ask ``importlib.metadata``)."""
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
    the cache is left to pydantic, which reads that variable itself. Either way pydantic's loader
    is imported with ``importlib.metadata`` deferred where neither is imported yet (module
    docstring); the fill then happens as the loader is imported."""
    if LOADER not in sys.modules and METADATA not in sys.modules:
        with deferring():
            try:
                importlib.import_module(LOADER)
            except ImportError:
                return False
        return _filled
    try:
        from pydantic.plugin import _loader
    except ImportError:
        return False
    return _fill(_loader)


_filled = False  # the last import of the loader through _DeferringLoader filled its cache


def _fill(loader: ModuleType) -> bool:
    """``loader._plugins = {}`` where the scan is sure no plugin is declared (see above)."""
    if os.environ.get("PYDANTIC_DISABLE_PLUGINS") is not None:
        return False
    if getattr(loader, "_plugins", ()) is not None or getattr(loader, "_loading_plugins", True) is not False:
        return False  # pydantic already looked (or is looking), or keeps its cache elsewhere
    if declares_plugins() is not False:
        return False
    loader._plugins = {}  # type: ignore[attr-defined]
    return True


@contextlib.contextmanager
def deferring() -> Iterator[None]:
    """While inside: an import of pydantic's loader (by anyone: robocfg's models, typer's parameter
    adapters) runs with ``importlib.metadata`` deferred and fills the cache (:func:`_fill`).
    The ``robocfg`` command stays inside from its start to its end (``robocfg.cli.app.main``);
    otherwise only :func:`skip_empty_plugin_scan` enters it, around its own import."""
    if _LoaderFinder in sys.meta_path:
        yield
        return
    sys.meta_path.insert(0, _LoaderFinder)
    try:
        yield
    finally:
        with contextlib.suppress(ValueError):
            sys.meta_path.remove(_LoaderFinder)


class _LoaderFinder:
    """The ``sys.meta_path`` entry of :func:`deferring`: finds pydantic's loader as the path finder
    does, with its execution wrapped (:class:`_DeferringLoader`); every other module, and the
    loader once ``importlib.metadata`` is imported, it leaves to the finders after it."""

    @staticmethod
    def find_spec(name: str, path: Sequence[str] | None = None, target: ModuleType | None = None) -> ModuleSpec | None:
        if name != LOADER or METADATA in sys.modules:
            return None
        spec = PathFinder.find_spec(name, path, target)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return None
        spec.loader = cast("Loader", _DeferringLoader(spec.loader))  # a loader by protocol (no importlib.abc)
        return spec


class _DeferringLoader:
    """Executes pydantic's loader module with its own loader (its bytecode), its import of
    ``importlib.metadata`` answered by :class:`_DeferredMetadata` meanwhile (through
    ``builtins.__import__`` for that one statement of that one module; ``sys.modules`` is left
    alone); then fills its cache (:func:`_fill`). The module is left with its own loader in
    ``__loader__`` and ``__spec__.loader``."""

    def __init__(self, loader: Loader) -> None:
        self.loader = loader

    def create_module(self, spec: ModuleSpec) -> ModuleType | None:
        return self.loader.create_module(spec)

    def exec_module(self, module: ModuleType) -> None:
        global _filled
        if module.__spec__ is not None:
            module.__spec__.loader = self.loader
        module.__loader__ = self.loader
        stand_in = _DeferredMetadata(METADATA)
        namespace = module.__dict__
        own_import = builtins.__import__

        def scoped_import(name: str, globals: Mapping[str, object] | None = None,
                          locals: Mapping[str, object] | None = None, fromlist: Sequence[str] | None = (),
                          level: int = 0) -> ModuleType:
            # the stand-in answers only the loader's own import of importlib.metadata: ``from
            # importlib.metadata import ...`` (pydantic ≥ 2.14) or ``import importlib.metadata as
            # ...`` (2.13: the ``importlib`` package it gives holds the stand-in as ``metadata``);
            # any other import, in any thread, is the interpreter's (``sys.modules`` never holds
            # the stand-in: another thread importing importlib.metadata meanwhile would get it)
            if name == METADATA and not level and globals is namespace:
                return stand_in if fromlist else _DeferredPackage(stand_in)
            return own_import(name, globals, locals, fromlist or (), level)

        builtins.__import__ = scoped_import
        try:
            self.loader.exec_module(module)
        finally:
            if builtins.__import__ is scoped_import:
                builtins.__import__ = own_import
        _filled = _fill(module)


class _DeferredMetadata(ModuleType):
    """What pydantic's loader module imports from ``importlib.metadata`` as it is executed: its
    ``entry_points`` imports the real module and calls the real function; any other attribute
    is the real module's (imported at that access; the module attributes the import system asks for,
    ``__path__`` for one, are absent as on a plain module)."""

    @staticmethod
    def entry_points(**params: object) -> object:
        """``importlib.metadata.entry_points(**params)``."""
        return _real_metadata().entry_points(**params)

    def __getattr__(self, name: str) -> object:
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(_real_metadata(), name)


class _DeferredPackage(ModuleType):
    """The ``importlib`` package as ``import importlib.metadata [as name]`` gives it to pydantic's
    loader: its ``metadata`` is the stand-in, any other attribute the real package's."""

    def __init__(self, metadata: _DeferredMetadata) -> None:
        super().__init__("importlib")
        self.metadata = metadata

    def __getattr__(self, name: str) -> object:
        return getattr(importlib, name)


def _real_metadata() -> ModuleType:
    """The real ``importlib.metadata`` (imported now if it is not yet)."""
    return importlib.import_module(METADATA)
