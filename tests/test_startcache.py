"""robocfg.startcache: the methods dataclasses generates are the same code with and without the
cache (a compile found in the file or made afresh), behave the same, and the cache file is
optional in every way (missing, corrupt, foreign, unwritable, off). Only processes robocfg owns
install it. What a process does, not how fast: benchmarks/bench_startup.py measures the time."""

from __future__ import annotations

import dataclasses
import json
import marshal
import os
import subprocess
import sys
import types
from collections.abc import Iterator
from pathlib import Path

import pytest

from robocfg import collector, startcache

ROOT = Path(__file__).resolve().parents[1]

# A fingerprint of every dataclass's generated methods in the modules loaded: the code objects
# (bytecode, constants, names, flags, positions), the functions' annotations, signatures,
# defaults and closure contents (addresses in reprs blanked). Printed as one JSON line.
_FINGERPRINT = r'''
import dataclasses, inspect, json, re, sys, types

def scrub(value):
    if isinstance(value, frozenset):  # a set literal's constant: its order follows the hash seed and insertions
        return "frozenset(" + repr(sorted(value, key=repr)) + ")"
    return re.sub(r" at 0x[0-9a-f]+", "", repr(value))

def code_fp(c):
    fields = ("co_argcount", "co_posonlyargcount", "co_kwonlyargcount", "co_nlocals", "co_stacksize",
              "co_flags", "co_names", "co_varnames", "co_freevars", "co_cellvars", "co_name",
              "co_qualname", "co_firstlineno", "co_filename")
    fp = {f: getattr(c, f) for f in fields if hasattr(c, f)}
    fp["co_code"] = c.co_code.hex()
    fp["co_linetable"] = c.co_linetable.hex()
    fp["co_exceptiontable"] = getattr(c, "co_exceptiontable", b"").hex()
    fp["co_consts"] = [code_fp(k) if isinstance(k, types.CodeType) else scrub(k) for k in c.co_consts]
    return fp

def function_fp(fn):
    fn = getattr(fn, "__wrapped__", fn)  # __repr__ is wrapped by dataclasses' recursion guard
    return {"code": code_fp(fn.__code__), "qualname": fn.__qualname__, "module": fn.__module__,
            "annotations": scrub(fn.__annotations__), "signature": scrub(inspect.signature(fn)),
            "defaults": scrub(fn.__defaults__), "kwdefaults": scrub(fn.__kwdefaults__),
            "closure": [scrub(cell.cell_contents) for cell in fn.__closure__ or ()]}

def fingerprint():
    out = {}
    for name, module in sorted(sys.modules.items()):
        for value in list(vars(module).values()):
            if isinstance(value, type) and dataclasses.is_dataclass(value) and value.__module__ == name:
                out[f"{name}.{value.__qualname__}"] = {
                    attr: function_fp(fn) for attr, fn in sorted(vars(value).items())
                    if isinstance(fn, types.FunctionType)
                    and getattr(getattr(fn, "__wrapped__", fn), "__code__").co_filename == "<string>"}
    return out
'''

# the start of a pick-place process as the bench child (a pool worker's start) makes it
_START = _FINGERPRINT + r'''
from robocfg import collector, startcache
collector.pause()
from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
session = open_session(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=0, episodes=1))
codes = startcache._codes or {}
print(json.dumps({"installed": startcache.installed(), "entries": len(codes), "new": startcache._new,
                  "file": str(startcache.path()), "classes": fingerprint()}))
session.close()
'''


def _child(code: str, cache: Path, *, off: bool = False, python: str = sys.executable) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", startcache.OFF_VARIABLE)}
    env.update(PYTHONPATH=str(ROOT), ROBOCFG_CACHE_DIR=str(cache))
    if off:
        env[startcache.OFF_VARIABLE] = "1"
    out = subprocess.run([python, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.splitlines()[-1])


def test_a_process_start_makes_the_same_methods_with_the_cache_from_file(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    off = _child(_START, cache, off=True)
    assert not off["installed"] and not cache.exists()
    first = _child(_START, cache)  # compiles every text and writes the file once its world is built
    assert first["installed"] and first["new"] == 0 and first["entries"] > 300
    assert Path(first["file"]).is_file()
    again = _child(_START, cache)  # every text found in the file: nothing compiled
    assert again["entries"] == first["entries"] and again["new"] == 0
    robocfg_classes = [name for name in off["classes"] if name.startswith("robocfg.")]
    assert len(robocfg_classes) > 40 and any(name.startswith("pydantic") for name in off["classes"])
    assert first["classes"] == off["classes"]
    assert again["classes"] == off["classes"]


@pytest.fixture
def fresh_cache(tmp_path: Path, monkeypatch) -> Iterator[Path]:
    """An empty start-up cache in ``tmp_path`` for this process, writable, uninstalled after."""
    monkeypatch.setenv("ROBOCFG_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv(startcache.OFF_VARIABLE, raising=False)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    for name, value in (("_codes", None), ("_used", set()), ("_new", 0)):
        monkeypatch.setattr(startcache, name, value)
    assert not startcache.installed()
    yield tmp_path
    startcache.uninstall()
    assert "exec" not in vars(dataclasses)


_PLAIN = '''
import dataclasses
from typing import ClassVar

@dataclasses.dataclass
class Point:
    x: float
    y: float = 0.0
    tags: list = dataclasses.field(default_factory=list)
    kind: ClassVar[str] = "point"

@dataclasses.dataclass(frozen=True, order=True)
class Frozen:
    name: str
    size: int = 3
    extra: tuple = dataclasses.field(default=(), compare=False, repr=False)

@dataclasses.dataclass(kw_only=True, slots=True)
class Keywords:
    a: int
    b: "Point | None" = None

@dataclasses.dataclass(unsafe_hash=True)
class Hashed:
    k: int
    v: float = dataclasses.field(default=1.5, hash=False)
'''


def _plain_classes(future: bool) -> dict:
    """The classes of ``_PLAIN``, made now (with or without ``from __future__ import annotations``
    in their module)."""
    module = _module(("from __future__ import annotations\n" if future else "") + _PLAIN)
    return {name: getattr(module, name) for name in ("Point", "Frozen", "Keywords", "Hashed")}


def _module(source: str) -> types.ModuleType:
    """A module made from ``source`` (compiled without this file's ``__future__`` flags)."""
    module = types.ModuleType("plain_module")  # dataclasses reads the module of a string annotation
    sys.modules["plain_module"] = module
    try:
        exec(compile(source, "plain_module.py", "exec", dont_inherit=True), vars(module))
    finally:
        del sys.modules["plain_module"]
    return module


def _fingerprints(classes: dict) -> dict:
    namespace: dict = {}
    exec(_FINGERPRINT, namespace)
    fp = namespace["function_fp"]
    return {name: {attr: fp(fn) for attr, fn in sorted(vars(cls).items()) if callable(fn)
                   and getattr(getattr(fn, "__wrapped__", fn), "__code__", None) is not None
                   and getattr(fn, "__wrapped__", fn).__code__.co_filename == "<string>"}
            for name, cls in classes.items()}


def _behaviour(c: dict) -> list:
    """What the classes do: init, repr, eq, order, hash, frozen errors, replace, asdict."""
    p = c["Point"](1.0, tags=["a"])
    f = c["Frozen"]("cube", extra=(1,))
    k = c["Keywords"](a=2, b=p)
    h = c["Hashed"](3)
    out: list = [repr(p), repr(f), repr(k), repr(h), p == c["Point"](1.0, 0.0, ["a"]), p != c["Point"](2.0),
                 f == c["Frozen"]("cube"), f < c["Frozen"]("dice"), hash(f) == hash(c["Frozen"]("cube", 3)),
                 hash(h) == hash(c["Hashed"](3, 9.0)), dataclasses.asdict(k), dataclasses.astuple(f),
                 repr(dataclasses.replace(f, size=5)), c["Point"].__hash__ is None]
    for bad in (lambda: setattr(f, "size", 4), lambda: delattr(f, "name"), lambda: c["Keywords"](2),
                lambda: c["Point"](), lambda: c["Frozen"]("a", 1, (), 4)):
        try:
            bad()
        except Exception as exc:
            out.append(f"{type(exc).__name__}: {exc}")
        else:
            out.append("no error")
    return out


@pytest.mark.parametrize("future", [False, True], ids=["annotations", "postponed-annotations"])
def test_plain_dataclasses_get_the_same_methods_compiled_or_from_the_file(fresh_cache: Path, future: bool) -> None:
    builtin = _plain_classes(future)
    startcache.install()
    assert vars(dataclasses)["exec"] is startcache.cached_exec
    compiled = _plain_classes(future)  # compiled by the cache, kept
    assert startcache._new > 0
    startcache.save()
    assert startcache.path().is_file()
    startcache._codes, startcache._new = None, 0  # read again from the file, as a new process
    from_file = _plain_classes(future)
    assert startcache._new == 0 and startcache._codes
    for made in (compiled, from_file):
        assert _fingerprints(made) == _fingerprints(builtin)
        assert _behaviour(made) == _behaviour(builtin)
    if not future:
        assert builtin["Point"].__init__.__annotations__["x"] is float  # not a string: not inherited


def test_other_interpreters_get_the_same_methods(tmp_path: Path) -> None:
    """On the other CPython versions installed here (3.12 and 3.13 build a class's methods in one
    ``exec``), as far as they exist: plain classes only, robocfg's dependencies are not there."""
    code = _FINGERPRINT + f"_PLAIN = {_PLAIN!r}\n" + r'''
import os
from robocfg import startcache
def made():
    module = types.ModuleType("plain_module")
    sys.modules["plain_module"] = module
    ns = vars(module)
    exec(compile(_PLAIN, "plain_module.py", "exec", dont_inherit=True), ns)
    return {n: {a: function_fp(f) for a, f in sorted(vars(ns[n]).items()) if isinstance(f, types.FunctionType)
                and getattr(f, "__wrapped__", f).__code__.co_filename == "<string>"}
            for n in ("Point", "Frozen", "Keywords", "Hashed")}
builtin = made()
startcache.install()
compiled = made()
startcache.save()
startcache._codes, startcache._new = None, 0
from_file = made()
def differ(a, b, path=""):
    if a == b:
        return []
    if isinstance(a, dict) and isinstance(b, dict) and a.keys() == b.keys():
        return [d for k in a for d in differ(a[k], b[k], f"{path}/{k}")]
    return [f"{path}: {a!r:.300} != {b!r:.300}"]
print(json.dumps({"differ": differ(builtin, compiled) + differ(builtin, from_file),
                  "hits": startcache._new == 0 and len(startcache._codes) > 0}))
'''
    found = [p for p in Path("/root/.pyenv/versions").glob("3.1[23].*/bin/python3")] if Path("/root/.pyenv").is_dir() else []
    if not found:
        pytest.skip("no other CPython 3.12/3.13 installed here")
    for python in found:
        assert _child(code, tmp_path / python.parent.parent.name, python=str(python)) == {"differ": [], "hits": True}, python


def test_the_file_is_optional_in_every_way(fresh_cache: Path) -> None:
    startcache.install()
    file = startcache.path()
    assert file is not None and file.parent == fresh_cache
    valid = None
    for content in (None, b"", b"garbage", b"robocfg-dataclass-code\n" + b"\0" * 40, "truncated", "crc",
                    "other-magic", "not-a-dict", "bad-entry"):
        startcache._codes, startcache._new = None, 0
        if content is None:
            file.unlink(missing_ok=True)
        elif isinstance(content, bytes):
            file.write_bytes(content)
        else:
            payload = marshal.dumps([1] if content == "not-a-dict" else
                                    {text: 7 for text in valid} if content == "bad-entry" else valid)
            data = startcache._header(payload) + payload
            if content == "truncated":
                data = data[:-10]
            elif content == "crc":
                data = data[:-1] + bytes([data[-1] ^ 1])
            elif content == "other-magic":
                data = data.replace(startcache.MAGIC_NUMBER, b"\0\0\r\n", 1)
            file.write_bytes(data)
        classes = _plain_classes(False)
        assert _behaviour(classes)
        assert startcache._new > 0, content  # nothing usable read: compiled afresh
        startcache.save()  # and written again, whole
        valid = {k: v for k, v in startcache._codes.items()}
        startcache._codes, startcache._new = None, 0
        _plain_classes(False)
        assert startcache._new == 0, content


def test_unwritable_folder_dont_write_bytecode_and_the_bound(fresh_cache: Path, monkeypatch) -> None:
    startcache.install()
    blocker = fresh_cache / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("ROBOCFG_CACHE_DIR", str(blocker / "cache"))  # cannot be made: ignored silently
    _plain_classes(False)
    startcache.save()
    assert not list(fresh_cache.glob("**/*.tmp"))
    monkeypatch.setenv("ROBOCFG_CACHE_DIR", str(fresh_cache))
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    startcache.save()
    assert not startcache.path().exists()  # PYTHONDONTWRITEBYTECODE: nothing written
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    startcache.save()
    everything = dict(startcache._codes)
    assert startcache.path().is_file() and len(everything) > 4
    startcache._codes, startcache._new, startcache._used = None, 0, set()
    monkeypatch.setattr(startcache, "MAX_ENTRIES", 3)
    _module("import dataclasses\n@dataclasses.dataclass\nclass One:\n    only: int\n")
    startcache.save()  # past the bound: only what this process used
    startcache._codes = None
    assert set(startcache._load()) == startcache._used and len(startcache._used) < len(everything)


def test_the_switch_turns_it_off(fresh_cache: Path, monkeypatch) -> None:
    monkeypatch.setenv(startcache.OFF_VARIABLE, "1")
    startcache.install()
    assert not startcache.installed() and "exec" not in vars(dataclasses)


def test_a_dataclasses_with_future_imports_is_left_alone(fresh_cache: Path, monkeypatch) -> None:
    """The builtin exec compiles with its caller's __future__ flags and the cache with none: a
    dataclasses module that imported from __future__ would get other code from the cache, so
    install() stays out of it."""
    import __future__

    monkeypatch.setattr(dataclasses, "annotations", __future__.annotations, raising=False)
    startcache.install()
    assert not startcache.installed() and "exec" not in vars(dataclasses)
    monkeypatch.delattr(dataclasses, "annotations")
    startcache.install()
    assert startcache.installed() and vars(dataclasses)["exec"] is startcache.cached_exec
    startcache.uninstall()


def test_no_home_directory_means_no_cache_not_an_error(fresh_cache: Path, monkeypatch) -> None:
    """HOME unset and a uid without a passwd entry (a container run as an arbitrary user):
    ``Path.home()`` raises RuntimeError; every dataclass the command made failed with it (an
    "internal error" for every ``robocfg`` command, where the start before the cache worked)."""
    import pwd

    for name in ("ROBOCFG_CACHE_DIR", "XDG_CACHE_HOME", "HOME"):
        monkeypatch.delenv(name, raising=False)

    def no_entry(uid: int) -> pwd.struct_passwd:
        raise KeyError(f"getpwuid(): uid not found: {uid}")

    monkeypatch.setattr(pwd, "getpwuid", no_entry)
    with pytest.raises(RuntimeError):
        Path.home()  # what the environment above makes of the default folder
    startcache.install()
    assert startcache.path() is None
    assert _behaviour(_plain_classes(False))  # made, compiled afresh
    startcache.save()  # nowhere to write: nothing, silently
    assert not list(fresh_cache.iterdir())


def test_only_the_command_installs_it_and_gives_dataclasses_back(fresh_cache: Path, capsys, monkeypatch) -> None:
    from _cli import run_main

    code, _, err = run_main(["validate", "robocfg/data/robots/panda.yaml"], capsys, monkeypatch)
    assert code == 0, err
    assert not startcache.installed() and "exec" not in vars(dataclasses)
    collector.pause()
    assert startcache.installed()
    collector.resume()  # the start is over: written, still installed for the process's later classes
    assert startcache.installed()
    collector.restore()
    assert not startcache.installed() and "exec" not in vars(dataclasses)


_PROGRAM = r'''
import dataclasses, json
import robocfg
from robocfg.engine import RunOptions, open_session
with open_session(robocfg.load_task("pick_place"), RunOptions(seed=0, episodes=1)) as session:
    session.run(0)
from robocfg import startcache
print(json.dumps({"shadowed": "exec" in vars(dataclasses), "installed": startcache.installed()}))
'''


def test_a_program_that_imports_robocfg_keeps_its_dataclasses(tmp_path: Path) -> None:
    assert _child(_PROGRAM, tmp_path) == {"shadowed": False, "installed": False}
    assert not list(tmp_path.glob("dataclasses.*"))
