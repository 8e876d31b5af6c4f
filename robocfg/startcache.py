"""A bytecode cache, kept between processes, for the methods :mod:`dataclasses` generates.

For every dataclass, CPython's ``dataclasses`` writes the source text of its ``__init__``,
``__repr__``, ``__eq__``, ``__hash__``, ``__setattr__``/``__delattr__`` and compiles it with
``exec(text, globals, ns)`` (3.11 and 3.12: one ``exec`` per method; 3.13: one per class). A
robocfg process creates ≈ 110 dataclasses before its world is built (60 robocfg's own, 50 of
pydantic's and annotated_types' modules), ≈ 1 ms each on the 2-core laptop, more than half of it
the ``compile`` of that text. The text of a class is the same in every process, so its code
object can be kept, as ``__pycache__`` keeps a module's.

:func:`install` shadows the name ``exec`` in the ``dataclasses`` module's globals (a module's
globals come before the builtins), so the stdlib builds its text as it always does; only the
compile of a ``str`` source is looked up by that exact text, and on a miss compiled exactly as the
builtin ``exec`` compiles it from ``dataclasses``' frame: ``compile(text, "<string>", "exec",
dont_inherit=True)`` (``dataclasses`` has no ``__future__`` imports; inheriting this module's or a
caller's would change the code, e.g. turn the annotations into strings). The code object is then
run by the builtin ``exec`` with the same globals and locals; any other call shape goes to the
builtin unchanged. This module has no ``from __future__ import annotations`` for the same reason:
a source handed on to the builtin from here inherits this module's compiler flags.

The file: ``dataclasses.<cache_tag>[.opt-N].m<marshal version>.bin`` in robocfg's cache folder
(:func:`robocfg.cachedir.cache_dir`), read once at the first lookup (a process that creates no
dataclass never reads it). A header (:data:`MAGIC`, the interpreter's bytecode magic number, a
CRC-32 of the payload) guards the marshalled dict from text to code object: a missing, unreadable,
corrupt, foreign or other-interpreter file is ignored, and rewritten at the next :func:`save`.
:func:`save` writes (a temporary file, then :func:`os.replace`) only when new entries appeared,
not when ``sys.dont_write_bytecode`` (``PYTHONDONTWRITEBYTECODE``, as for ``__pycache__``); an
unwritable folder is ignored silently. Past :data:`MAX_ENTRIES` it starts afresh with the entries
this process used. ``ROBOCFG_NO_START_CACHE`` (any non-empty value) turns it off.

Only processes robocfg owns install it, through :mod:`robocfg.collector` (whose ``pause`` marks
the start of such a process: the ``robocfg`` command, a pool worker, a Ray actor; ``resume``
saves, ``restore`` saves and uninstalls) and the process pool's fork server
(:mod:`robocfg.executors.boot`). A program that imports robocfg keeps its ``dataclasses``
untouched.
"""

import __future__

import builtins
import contextlib
import dataclasses
import marshal
import os
import sys
import zlib
from importlib.util import MAGIC_NUMBER
from pathlib import Path
from types import CodeType

from robocfg.cachedir import cache_dir

MAGIC = b"robocfg-dataclass-code\n"  # the file's first bytes: a file of another kind is ignored
MAX_ENTRIES = 4096  # past this many texts a save starts afresh with the ones this process used
MAX_BYTES = 16 << 20  # a larger file is not read
OFF_VARIABLE = "ROBOCFG_NO_START_CACHE"

_codes: dict[str, CodeType] | None = None  # text -> code object; None until the file is read
_used: set[str] = set()  # the texts this process looked up or compiled
_new = 0  # entries compiled since the file was read or last written
_installed = False


def install() -> None:
    """Let ``dataclasses`` find its generated methods' code in the cache (module docstring).
    Nothing when ``ROBOCFG_NO_START_CACHE`` is set, when already installed, when something else
    shadows ``exec`` in ``dataclasses``, or when ``dataclasses`` imports from ``__future__``."""
    global _installed
    if _installed or os.environ.get(OFF_VARIABLE) or "exec" in vars(dataclasses) or _has_future(dataclasses):
        return
    dataclasses.exec = cached_exec  # type: ignore[attr-defined]
    _installed = True


def _has_future(module: object) -> bool:
    """Whether ``module`` has a ``from __future__ import ...`` (the name is bound to a feature
    object in its globals). The builtin ``exec`` compiles a source with its caller's future flags;
    the cache compiles with none (:func:`_code`), so it stays out of a ``dataclasses`` that has
    any (none has to this day: 3.11 to 3.13)."""
    feature = type(__future__.annotations)
    return any(type(value) is feature for value in vars(module).values())


def uninstall() -> None:
    """Save new entries (:func:`save`) and give ``dataclasses`` the builtin ``exec`` back."""
    global _installed
    if not _installed:
        return
    save()
    if vars(dataclasses).get("exec") is cached_exec:
        del dataclasses.exec  # type: ignore[attr-defined]
    _installed = False


def installed() -> bool:
    """Whether :func:`install` is in effect."""
    return _installed


def cached_exec(source: object, globals: dict[str, object] | None = None,
                locals: object = None, /, **kwargs: object) -> None:
    """The builtin ``exec``, with the compile of a ``str`` source looked up in the cache."""
    if globals is None:  # the builtin's "current scope" is its caller's: dataclasses' frame
        frame = sys._getframe(1)
        globals = frame.f_globals
        if locals is None:
            locals = frame.f_locals
    if type(source) is str:
        source = _code(source)
    builtins.exec(source, globals, locals, **kwargs)  # type: ignore[arg-type]


def _code(text: str) -> CodeType:
    """The code object of ``text`` compiled as the builtin ``exec`` would from ``dataclasses``."""
    global _codes, _new
    codes = _codes if _codes is not None else _load()
    code = codes.get(text)
    if type(code) is not CodeType:
        code = compile(text, "<string>", "exec", dont_inherit=True)
        codes[text] = code
        _new += 1
    _used.add(text)
    return code


def path() -> Path | None:
    """The cache file of this interpreter (bytecode tag, optimisation level, marshal format), or
    None where the interpreter has no bytecode tag or the cache folder has no home directory to
    be in (:func:`robocfg.cachedir.cache_dir` raises RuntimeError)."""
    tag = sys.implementation.cache_tag
    if tag is None:
        return None
    try:
        folder = cache_dir()
    except RuntimeError:  # no home directory (HOME unset, a uid without a passwd entry): no cache
        return None
    opt = f".opt-{sys.flags.optimize}" if sys.flags.optimize else ""
    return folder / f"dataclasses.{tag}{opt}.m{marshal.version}.bin"


def _header(payload: bytes) -> bytes:
    return MAGIC + MAGIC_NUMBER + zlib.crc32(payload).to_bytes(4, "little")


def _load() -> dict[str, CodeType]:
    """Read the file once (an empty cache where it is missing, unreadable, too big, corrupt or
    foreign)."""
    global _codes
    _codes = {}
    file = path()
    if file is None:
        return _codes
    try:
        with open(file, "rb") as f:
            data = f.read(MAX_BYTES + 1)
    except OSError:
        return _codes
    head = len(_header(b""))
    if len(data) > MAX_BYTES or len(data) < head:
        return _codes
    payload = data[head:]
    if data[:head] != _header(payload):
        return _codes
    try:
        loaded = marshal.loads(payload)
    except (ValueError, EOFError, TypeError):
        return _codes
    if type(loaded) is dict:
        _codes = loaded  # entries are checked as they are looked up (_code)
    return _codes


def save() -> None:
    """Write the cache file if this process compiled new entries (module docstring); errors are
    ignored (the cache is an optimisation only)."""
    global _codes, _new
    if not _new or _codes is None or sys.dont_write_bytecode:
        return
    file = path()
    if file is None:
        return
    if len(_codes) > MAX_ENTRIES:
        _codes = {text: _codes[text] for text in _used if text in _codes}
    payload = marshal.dumps(_codes)
    tmp = file.with_name(f"{file.name}.{os.getpid()}.tmp")
    try:
        file.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as f:
            f.write(_header(payload) + payload)
        os.replace(tmp, file)
    except OSError:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        return
    _new = 0
