"""What a pool worker does to its own process before it opens its recipe: one core's worth of work.

*Math threads.* numpy's and scipy's OpenBLAS (MKL, an OpenMP runtime alike) start a thread per
core in every process that loads them, and after a call they split, those threads spin waiting
for the next one before they sleep. A worker is one core's worth of work by design — the pool
runs one per core — so those threads can only take cores from the other workers or, with idle
cores, burn CPU nobody asked for (on the lent 16-core machine a 1-worker pool's first episode cost
680–870 ms of process CPU against 121–237 ms in a Ray actor, whose Ray sets ``OMP_NUM_THREADS``,
which OpenBLAS honours). So the pool's fork server, before it imports numpy
(:mod:`robocfg.executors.boot`), sets ``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS`` and
``MKL_NUM_THREADS`` to 1 — unless the user set any of them: then they keep what they set — and
neither it nor its workers start math threads (a library loaded before that — a
``sitecustomize`` that imports numpy, as on the lent machine — is told there through its setter,
so the workers forked from the server inherit a count of 1 and never start its threads). A
worker whose :class:`WorkerSetup` asks for another count (``math_threads=None``: the libraries' default, a thread per core: the old
behaviour, which a benchmark runs beside the new) sets the variables for libraries it loads later
and tells the ones already loaded through their own ``*_set_num_threads`` (found among the
process's loaded shared objects, as threadpoolctl finds them; Linux ``/proc``) — called only
where the count differs, since OpenBLAS starts its thread pool on that call. The numbers a
worker computes are the same either way: one thread runs the same kernels. A Ray actor gets
``OMP_NUM_THREADS`` from Ray; :func:`follow_omp_threads` makes libraries it loaded before that
follow it.

*Pinning* (``pin=True``, off by default: measure it first): worker i is bound to core
``i mod n`` of the cores the driver may use (``os.sched_setaffinity``).

*malloc* (``malloc=True``, off by default: measure it first): glibc's dynamic mmap threshold and
heap trimming switched off (``mallopt``), so large temporaries reuse heap pages instead of being
mapped, faulted in and unmapped on every call.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from dataclasses import dataclass

MATH_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
# run-time (setter, getter) of each library's thread count (numpy's and scipy's wheels rename OpenBLAS's)
_SETTERS = (("openblas_set_num_threads", "openblas_get_num_threads"),
            ("openblas_set_num_threads64_", "openblas_get_num_threads64_"),
            ("scipy_openblas_set_num_threads", "scipy_openblas_get_num_threads"),
            ("scipy_openblas_set_num_threads64_", "scipy_openblas_get_num_threads64_"),
            ("MKL_Set_Num_Threads", "MKL_Get_Max_Threads"), ("omp_set_num_threads", "omp_get_max_threads"))
_LIBRARY_HINTS = ("openblas", "mkl_rt", "libgomp", "libomp", "libiomp")
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # glibc mallopt parameters
MALLOC_MMAP_THRESHOLD = 64 << 20  # bytes: allocations below it come from the heap
MALLOC_TRIM_THRESHOLD = 512 << 20  # bytes of free heap top kept before it is returned to the system
_SET_HERE: list[str] = []  # the variables single_threaded_env set in this process (a fork server's, inherited)


@dataclass(frozen=True)
class WorkerSetup:
    """How each pool worker sets up its process (see the module docstring).

    ``math_threads``: threads each math library may use in a worker (None: the libraries' own
    default, a thread per core: what a pool did before); ``pin``: bind worker i to core i mod n; ``malloc``: keep large
    temporaries on the heap (glibc)."""

    math_threads: int | None = 1
    pin: bool = False
    malloc: bool = False


@dataclass(frozen=True)
class SetupDone:
    """What :func:`apply` did in a worker: the loaded libraries it told their thread count (file
    name: setter; none when they had it already), whether the user's variables were kept, the core it was bound to (None: not bound), whether
    mallopt took the settings."""

    libraries: tuple[str, ...] = ()
    user_kept: bool = False
    core: int | None = None
    malloc: bool = False


def single_threaded_env() -> tuple[str, ...]:
    """Set the math libraries' thread variables to 1 in this process's environment unless the user
    set any of them (a pool's fork server, before numpy is imported); returns those it set. A
    library loaded already (a ``sitecustomize`` that imports numpy) is told here too, so the
    processes forked from this one inherit its count of 1 and never start its threads."""
    if not _SET_HERE and not any(v in os.environ for v in MATH_THREAD_VARIABLES):
        _SET_HERE.extend(MATH_THREAD_VARIABLES)
        limit_math_threads(1)
    return tuple(_SET_HERE)


def apply(setup: WorkerSetup, index: int) -> SetupDone:
    """Set up this process as worker ``index`` of a pool (call it first thing in the worker)."""
    libraries: tuple[str, ...] = ()
    user_kept = any(v in os.environ and v not in _SET_HERE for v in MATH_THREAD_VARIABLES)
    if not user_kept:
        libraries = limit_math_threads(setup.math_threads)
    core = None
    if setup.pin and hasattr(os, "sched_setaffinity"):
        cores = sorted(os.sched_getaffinity(0))
        core = cores[index % len(cores)]
        os.sched_setaffinity(0, {core})
    return SetupDone(libraries, user_kept, core, _keep_on_heap() if setup.malloc else False)


def limit_math_threads(n: int | None) -> tuple[str, ...]:
    """Let the math libraries of this process use ``n`` threads (None: their default, one per core
    this process may use): the environment for those loaded later, each loaded one's own setter
    now where its count differs; returns ``file name:setter`` of the loaded ones told."""
    if n is None:
        for var in _SET_HERE:
            os.environ.pop(var, None)
        n = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    else:
        for var in MATH_THREAD_VARIABLES:
            os.environ[var] = str(n)
    told: list[str] = []
    for label, set_count, get_count in _math_libraries():
        if get_count() != n:
            set_count(n)
            told.append(label)
    return tuple(told)


def follow_omp_threads() -> tuple[str, ...]:
    """In a Ray actor: make the math libraries already loaded follow ``OMP_NUM_THREADS``, which Ray
    sets to the actor's CPUs unless it is set (a library loaded before Ray set it — a
    ``sitecustomize`` that imports numpy — would keep a thread per core); nothing when
    ``OPENBLAS_NUM_THREADS`` or ``MKL_NUM_THREADS`` is set or ``OMP_NUM_THREADS`` is not a count.
    Returns ``file name:setter`` of the libraries told."""
    omp = os.environ.get("OMP_NUM_THREADS", "")
    if "OPENBLAS_NUM_THREADS" in os.environ or "MKL_NUM_THREADS" in os.environ or not omp.isdigit() or int(omp) < 1:
        return ()
    return limit_math_threads(int(omp))


def math_threads() -> int:
    """The most threads any math library loaded in this process may use now (0: none loaded or
    none found): 1 in a pool worker unless set otherwise."""
    return max((get_count() for _, _, get_count in _math_libraries()), default=0)


def _math_libraries() -> Iterator[tuple[str, Callable[[int], None], Callable[[], int]]]:
    """``(file name:setter, setter, getter)`` of each thread-count setter among the math libraries
    loaded in this process, each once (a library that links another exposes its symbols too)."""
    import ctypes  # here, not at the top: the robocfg command imports this module for its constant

    seen: set[int] = set()
    for path in _loaded_libraries():
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for setter, getter in _SETTERS:
            fn, get = getattr(lib, setter, None), getattr(lib, getter, None)
            if fn is None or get is None:
                continue
            address = ctypes.cast(fn, ctypes.c_void_p).value or 0
            if address in seen:
                continue
            seen.add(address)
            fn.argtypes, fn.restype = [ctypes.c_int], None
            get.argtypes, get.restype = [], ctypes.c_int
            yield f"{os.path.basename(path)}:{setter}", fn, get


def _loaded_libraries() -> list[str]:
    """Paths of the math libraries mapped into this process (Linux ``/proc/self/maps``; none
    elsewhere)."""
    try:
        with open("/proc/self/maps") as f:
            paths = {line.split(maxsplit=5)[5].strip() for line in f if line.count(" ") >= 5 and "/" in line}
    except OSError:
        return []
    return sorted(p for p in paths if ".so" in p and any(h in os.path.basename(p).lower() for h in _LIBRARY_HINTS))


def _keep_on_heap() -> bool:
    """glibc: a fixed mmap threshold (no dynamic raise, no per-call maps for temporaries below
    it) and a high trim threshold; False where there is no glibc ``mallopt``."""
    import ctypes

    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = [ctypes.c_int, ctypes.c_int], ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MALLOC_MMAP_THRESHOLD)) and bool(mallopt(_M_TRIM_THRESHOLD, MALLOC_TRIM_THRESHOLD))
