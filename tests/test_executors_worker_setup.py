"""How a pool worker sets up its process (robocfg.executors.worker_setup): one math-library thread
by default (the libraries' own default, a thread per core, on request), optionally pinned to a
core; the records are the same whatever the setup."""

from __future__ import annotations

import os

import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions
from robocfg.executors import worker_setup
from robocfg.executors.pool import ProcessPool
from robocfg.executors.recipe import EngineRecipe
from robocfg.executors.session import plan_batches
from robocfg.executors.worker_setup import MATH_THREAD_VARIABLES, WorkerSetup

CORES = len(os.sched_getaffinity(0))


def _run(setup: WorkerSetup):
    recipe = EngineRecipe.of(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=3, episodes=2))
    pool = ProcessPool(2, setup)
    pool.start(recipe)
    return pool.starts, pool.run(recipe, plan_batches(2, 2, False))


@pytest.mark.skipif(CORES < 2 or any(v in os.environ for v in MATH_THREAD_VARIABLES),
                    reason="needs 2 cores (one core: the libraries start no thread either way) and no user setting")
def test_workers_start_no_math_threads_by_default_and_give_the_records_of_the_librarys_default():
    single_starts, single = _run(WorkerSetup())
    default_starts, default = _run(WorkerSetup(math_threads=None))
    pinned_starts, pinned = _run(WorkerSetup(pin=True, malloc=True))
    # the fork server set the variables before numpy was loaded: no library needed telling
    assert all(s.setup is not None and s.setup.libraries == () and not s.setup.user_kept for s in single_starts)
    # the library default: numpy's OpenBLAS (loaded before the worker began) told to use every core
    assert all(s.setup is not None and any("openblas" in lib for lib in s.setup.libraries) for s in default_starts)
    assert max(s.threads for s in single_starts) < min(s.threads for s in default_starts)
    assert [s.math_threads for s in single_starts] == [1, 1] and [s.math_threads for s in default_starts] == [CORES] * 2
    assert sorted(s.setup.core for s in pinned_starts if s.setup is not None) == sorted(os.sched_getaffinity(0))[:2]
    assert all(s.setup is not None and s.setup.malloc for s in pinned_starts)
    assert single.records == default.records == pinned.records and single.report == default.report == pinned.report
    usage = [r.usage for r in single.runs]
    assert all(u is not None and u.user > 0 and u.nvcsw >= 0 for u in usage)


def test_a_users_thread_variable_is_kept(monkeypatch):
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    monkeypatch.setattr(os, "environ", {**env, "OMP_NUM_THREADS": "3"})
    monkeypatch.setattr(worker_setup, "_SET_HERE", [])
    assert worker_setup.single_threaded_env() == ()
    done = worker_setup.apply(WorkerSetup(), 0)
    assert done.user_kept and done.libraries == ()
    assert os.environ["OMP_NUM_THREADS"] == "3" and "OPENBLAS_NUM_THREADS" not in os.environ


def test_the_fork_servers_variables_are_set_only_where_the_user_set_none(monkeypatch):
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    monkeypatch.setattr(os, "environ", env)
    monkeypatch.setattr(worker_setup, "_SET_HERE", [])
    told: list[int | None] = []
    monkeypatch.setattr(worker_setup, "limit_math_threads", lambda n: told.append(n) or ())
    assert worker_setup.single_threaded_env() == MATH_THREAD_VARIABLES and told == [1]
    assert not worker_setup.apply(WorkerSetup(), 0).user_kept  # its own setting is not the user's
    assert told == [1, 1]


def test_limit_math_threads_sets_the_variables_for_libraries_loaded_later(monkeypatch):
    monkeypatch.setattr(os, "environ", {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES})
    monkeypatch.setattr(worker_setup, "_loaded_libraries", lambda: [])  # leave this process's libraries alone
    assert worker_setup.limit_math_threads(1) == ()
    assert all(os.environ[v] == "1" for v in MATH_THREAD_VARIABLES)


@pytest.mark.skipif(CORES < 2 or any(v in os.environ for v in MATH_THREAD_VARIABLES),
                    reason="needs 2 cores and no user setting")
@pytest.mark.parametrize("limit", [False, True])
def test_a_fork_server_that_loaded_numpy_first_still_forks_single_threaded_workers(limit):
    """numpy imported before the fork server's first module (a sitecustomize): its OpenBLAS has a
    thread per core; told in the server, the processes forked from it split no call over threads."""
    import subprocess
    import sys

    code = ("import os, numpy as np\n"
            "from robocfg.executors.worker_setup import single_threaded_env\n"
            f"if {limit}: single_threaded_env()\n"
            "r, w = os.pipe()\n"
            "if os.fork() == 0:\n"
            "    a = np.ones((400, 400)); a @ a\n"
            "    os.write(w, str(len(os.listdir('/proc/self/task'))).encode()); os._exit(0)\n"
            "os.wait(); print(os.read(r, 16).decode())\n")
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    threads = int(out.stdout.strip())
    assert threads == 1 if limit else threads > 1


@pytest.mark.skipif(CORES < 2 or any(v in os.environ for v in MATH_THREAD_VARIABLES),
                    reason="needs 2 cores and no user setting")
def test_a_ray_actors_libraries_loaded_before_ray_set_omp_follow_it():
    """A Ray actor whose numpy was loaded before Ray set OMP_NUM_THREADS (a sitecustomize): its
    OpenBLAS keeps a thread per core until told; a user's OPENBLAS_NUM_THREADS is left alone."""
    import subprocess
    import sys

    code = ("import os, numpy as np\n"
            "from robocfg.executors.worker_setup import follow_omp_threads, math_threads\n"
            "before = math_threads(); os.environ['OMP_NUM_THREADS'] = '1'\n"
            "told = follow_omp_threads(); print(before, math_threads(), len(told))\n")
    env = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == [str(CORES), "1", "1"]
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**env, "OPENBLAS_NUM_THREADS": "2"}, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["2", "2", "0"]
