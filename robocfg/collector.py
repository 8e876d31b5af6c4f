"""The garbage collector during a process's start-up: no collections until the world is built.

A robocfg process's start (the imports, the task's validators, the world) creates ≈ 80 000
container objects — modules, classes, functions, pydantic schemas — that live as long as the
process. CPython's collector counts them as they are made and runs a generation-0 collection every
700 net new ones and a generation-1 every tenth of those: ≈ 100 collections before a pick-place
world is ready, which traverse the young objects again and again and free next to nothing
(≈ 0.025 s of the 0.55 s fixed start on the 2-core laptop; 0.06 s of a ``robocfg validate`` of
one task, whose last collections are full ones).

:func:`pause` raises the generation-0 threshold to :data:`START_THRESHOLD` (the start-up stays
below it; a longer command without a world, such as ``robocfg bench ik``, still collects, every
that many allocations). :func:`resume`, which the episode engine calls once a session's world
is built and its snapshot taken, moves every object alive then into the permanent generation
(:func:`gc.freeze`: later full collections do not traverse the start-up's objects again, and the
first collection after the start does not traverse all of them as young objects) and restores
the thresholds. Reference cycles that became garbage during the start stay allocated (the
start-up makes few of them). Nothing is frozen where a nanobind extension is loaded by then (it
would report the frozen objects as leaked at exit) or where the process froze objects itself.

The same start-up also binds the symbols of the extension libraries it loads lazily: :func:`pause`
sets :func:`sys.setdlopenflags` to ``RTLD_LAZY`` (CPython's default is ``RTLD_NOW``), and
:func:`resume`/:func:`restore` put the flags back. With ``RTLD_NOW`` the dynamic linker looks up
every function symbol of pinocchio's, coal's, eigenpy's, PyBullet's and the BLAS libraries'
bindings as each is loaded, most of which are never called; lazily, a function's symbol is looked
up at its first call. Callgrind (the bench child's path, pick-place, to the end of episode 0):
3 046 M -> 3 022 M instructions (-24 M; -24 M already at the world, so the first calls' lookups
cost next to nothing). The one difference: a library missing a symbol fails at the first call of
that function instead of at import (the wheels robocfg depends on resolve all of theirs).
``LD_BIND_NOW`` in the environment still binds everything at load.

Only processes robocfg owns pause: the ``robocfg`` command (``robocfg.cli.app.main``, which
puts the thresholds back with :func:`restore` as it returns, for a program or a test calling
it), a pool worker (``robocfg.executors.pool``) and a Ray actor (``robocfg.executors.ray_pool``).
A program that imports robocfg keeps its collector as it set it: :func:`resume` does nothing
where :func:`pause` was not called.

The same three marks drive the start-up code cache (:mod:`robocfg.startcache`: the compiled
methods of the dataclasses the start creates, kept between processes): :func:`pause` installs it,
:func:`resume` writes what is new (a pool worker ends with ``os._exit``, so not at exit),
:func:`restore` writes and uninstalls it.
"""

from __future__ import annotations

import gc
import os
import sys

from robocfg import startcache

START_THRESHOLD = 100_000  # net new container objects between generation-0 collections during the start

_saved: tuple[int, int, int] | None = None  # the thresholds pause() replaced
_froze = False  # resume() froze the objects alive then (restore() thaws them)
_dlopen_flags: int | None = None  # the dlopen flags pause() replaced


def pause() -> None:
    """Collect no garbage until :func:`resume` (or every :data:`START_THRESHOLD` allocations;
    nothing when the collector is disabled or already paused), and load extension libraries with
    lazy symbol binding until then (module docstring)."""
    global _saved
    if _saved is None and gc.isenabled():
        _saved = gc.get_threshold()
        gc.set_threshold(START_THRESHOLD, _saved[1], _saved[2])
        _lazy_binding()
    startcache.install()


def _lazy_binding() -> None:
    """Extension libraries loaded from now on bind their function symbols at first call."""
    global _dlopen_flags
    if _dlopen_flags is None and hasattr(sys, "setdlopenflags"):
        _dlopen_flags = sys.getdlopenflags()
        sys.setdlopenflags((_dlopen_flags & ~os.RTLD_NOW) | os.RTLD_LAZY)


def _bind_now() -> None:
    """The dlopen flags as before :func:`pause`."""
    global _dlopen_flags
    if _dlopen_flags is not None:
        sys.setdlopenflags(_dlopen_flags)
        _dlopen_flags = None


def resume() -> None:
    """After :func:`pause`: freeze the objects alive now (:func:`gc.freeze`; not when something
    froze objects before, nor when a nanobind extension is loaded, see :func:`nanobind_loaded`)
    and restore the thresholds; nothing otherwise."""
    global _saved, _froze
    if _saved is not None:
        if gc.get_freeze_count() == 0 and not nanobind_loaded():
            gc.freeze()
            _froze = True
        gc.set_threshold(*_saved)
        _saved = None
    _bind_now()
    startcache.save()


def restore() -> None:
    """The collector as before :func:`pause`: the thresholds back, the objects :func:`resume` froze
    thawed (:func:`gc.unfreeze`). The command's end calls it, for a program or a test that calls
    ``main()`` in its own process; the command's exit then does what it did
    (``robocfg.cli.process``)."""
    global _saved, _froze
    if _saved is not None:
        gc.set_threshold(*_saved)
        _saved = None
    if _froze:
        gc.unfreeze()
        _froze = False
    _bind_now()
    startcache.uninstall()


def nanobind_loaded() -> bool:
    """Whether a loaded extension module defines a nanobind type (its metaclass is nanobind's).
    nanobind prints every object of its own still alive at exit as a "leak" on stderr: frozen
    objects are, as are those the final collection would have freed (OMPL's bindings, which the
    planned pick-place mode uses; ruckig; trimesh's helpers)."""
    for module in list(sys.modules.values()):
        if (getattr(module, "__file__", None) or "").endswith(".py"):
            continue  # Python source: its classes are Python's
        for value in list(getattr(module, "__dict__", {}).values()):
            if isinstance(value, type) and type(value).__module__ == "nanobind":
                return True
    return False


def paused() -> bool:
    """Whether :func:`pause` is in effect."""
    return _saved is not None
