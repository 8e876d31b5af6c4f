"""The ``robocfg`` command's own process: one math-library thread, and no final garbage collection.

*Math threads* (:func:`single_math_thread`). numpy's and scipy's OpenBLAS each start a thread per
core as they load, which spins ≈ 0.05 s of CPU (2-core laptop) waiting for work before it sleeps:
robocfg's products are of 3..7-element vectors and matrices, which one thread computes. So the
command sets ``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS`` and ``MKL_NUM_THREADS`` to 1 before it
imports numpy, as a pool's fork server does for its workers
(:func:`robocfg.executors.worker_setup.single_threaded_env`, which also tells libraries loaded
already; not called here: its ``ctypes`` would cost every ``robocfg --help`` ≈ 5 ms) — unless the user set any of them, or numpy was loaded
before the command started.

*Exit* (:func:`skip_final_collection`). At exit CPython runs atexit handlers, then a full collection of every object still alive (the
modules, their classes, pydantic's schemas, numpy's and pinocchio's type objects: ≈ 50 000
container objects after a pick-place world), then tears the modules down. That collection and the
teardown's took 0.09–0.16 s of every ``robocfg validate`` process on the 2-core laptop (the
command's own work: 0.6 s), freeing memory the OS takes back anyway. :func:`skip_final_collection`
registers :func:`gc.freeze` as the first atexit handler, so it runs *after* every handler
registered later (a dataset writer's, Ray's, ``weakref.finalize``'s): what those handlers drop is
collected as before, and everything still alive then is left to the OS. Objects are still
released by reference counting at teardown; only the reference cycles alive at the very end are
no longer collected (Python does not promise to finalize those at exit either).

Not when a nanobind extension is loaded (OMPL's bindings, which the planned pick-place mode uses;
ruckig; trimesh's helpers): nanobind prints every instance, type and function of its own still
alive at exit as a "leak" on stderr, and those left in reference cycles would be. Such a process
exits as before.

Only the command line does either (``robocfg.cli.app.main``); a program that imports robocfg
keeps its own math threads and its interpreter's exit.
"""

from __future__ import annotations

import atexit
import gc
import os
import sys

from robocfg.collector import nanobind_loaded
from robocfg.executors.worker_setup import MATH_THREAD_VARIABLES

_registered = False


def single_math_thread() -> tuple[str, ...]:
    """Set the math libraries' thread variables to 1 unless the user set any, or numpy is loaded
    already (its OpenBLAS has read them: a program or a test calling ``main()`` keeps its
    environment); returns those set."""
    if "numpy" in sys.modules or any(v in os.environ for v in MATH_THREAD_VARIABLES):
        return ()
    os.environ.update(dict.fromkeys(MATH_THREAD_VARIABLES, "1"))
    return MATH_THREAD_VARIABLES


def skip_final_collection() -> None:
    """Freeze the garbage collector at exit, after the atexit handlers registered later (once per process)."""
    global _registered
    if not _registered:
        atexit.register(_freeze)
        _registered = True


def _freeze() -> None:
    if not nanobind_loaded():
        gc.freeze()


