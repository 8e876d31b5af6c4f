"""The garbage collector during a process's start-up: no collections until the world is built.

A robocfg process's start (the imports, the task's validators, the world) creates ≈ 70 000
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
start-up makes few of them).

Only processes robocfg owns pause: the ``robocfg`` command (``robocfg.cli.app.main``, which
puts the thresholds back with :func:`restore` as it returns, for a program or a test calling
it), a pool worker (``robocfg.executors.pool``) and a Ray actor (``robocfg.executors.ray_pool``).
A program that imports robocfg keeps its collector as it set it: :func:`resume` does nothing
where :func:`pause` was not called.
"""

from __future__ import annotations

import gc

START_THRESHOLD = 100_000  # net new container objects between generation-0 collections during the start

_saved: tuple[int, int, int] | None = None  # the thresholds pause() replaced


def pause() -> None:
    """Collect no garbage until :func:`resume` (or every :data:`START_THRESHOLD` allocations);
    nothing when the collector is disabled or already paused."""
    global _saved
    if _saved is None and gc.isenabled():
        _saved = gc.get_threshold()
        gc.set_threshold(START_THRESHOLD, _saved[1], _saved[2])


def resume() -> None:
    """After :func:`pause`: freeze the objects alive now (:func:`gc.freeze`) and restore the
    thresholds; nothing otherwise."""
    global _saved
    if _saved is not None:
        gc.freeze()
        gc.set_threshold(*_saved)
        _saved = None


def restore() -> None:
    """After :func:`pause`: the thresholds back, nothing frozen (the command's end, for a program
    or a test that calls ``main()`` in its own process); nothing otherwise."""
    global _saved
    if _saved is not None:
        gc.set_threshold(*_saved)
        _saved = None


def paused() -> bool:
    """Whether :func:`pause` is in effect."""
    return _saved is not None
