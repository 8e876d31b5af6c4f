"""The ``robocfg`` command's own process (robocfg.cli.process): one math-library thread from its
start, and the collector frozen at its exit; a program importing robocfg keeps its own. What a
fresh process does, not how fast: benchmarks/bench_startup.py measures the time."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from robocfg.executors.worker_setup import MATH_THREAD_VARIABLES

ROOT = Path(__file__).resolve().parents[1]
VALIDATE = ["validate", "robocfg/data/tasks/pick_place.yaml"]  # loads numpy and scipy's LAPACK (reach IK)

# printed at exit by a handler registered before main(): it runs after robocfg's
_PROBE = ("import atexit, gc, os, sys\n"
          "def _probe():\n"
          "    tasks = len(os.listdir('/proc/self/task')) if os.path.isdir('/proc/self/task') else -1\n"
          "    print('PROBE', os.environ.get('OPENBLAS_NUM_THREADS'), os.environ.get('OMP_NUM_THREADS'), tasks,\n"
          "          gc.get_freeze_count() > 0)\n"
          "atexit.register(_probe)\n")


def _probe(code: str, **env: str) -> list[str]:
    child = {k: v for k, v in os.environ.items() if k not in MATH_THREAD_VARIABLES}
    out = subprocess.run([sys.executable, "-c", _PROBE + code], cwd=ROOT, env=child | env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "leak" not in out.stderr
    return next(ln for ln in out.stdout.splitlines() if ln.startswith("PROBE")).split()[1:]


def _cli(argv: list[str]) -> str:
    return f"from robocfg.cli.app import main\nsys.argv = ['robocfg', *{argv!r}]\nmain()\n"


def test_the_command_runs_one_math_thread_and_freezes_the_collector_last() -> None:
    blas, omp, threads, frozen = _probe(_cli(VALIDATE))
    assert (blas, omp, frozen) == ("1", "1", "True")
    if threads != "-1":
        assert threads == "1"  # numpy's and scipy's OpenBLAS loaded, no worker thread started


def test_math_threads_chosen_by_the_user_are_kept() -> None:
    blas, omp, threads, _ = _probe(_cli(VALIDATE), OPENBLAS_NUM_THREADS="2")
    assert (blas, omp) == ("2", "None")
    if threads != "-1":
        assert threads == "3"  # the main thread and one worker each for numpy's and scipy's OpenBLAS


def test_a_program_importing_robocfg_keeps_its_math_threads_and_exit() -> None:
    blas, omp, _, frozen = _probe("import robocfg, numpy\nfrom robocfg.checks import load_task\n")
    assert (blas, omp, frozen) == ("None", "None", "False")


def test_handlers_a_command_registers_run_before_the_freeze() -> None:
    code = ("import robocfg.cli.process as p\n"
            "orig = p.skip_final_collection\n"
            "def wrapped():\n"
            "    orig()\n"
            "    atexit.register(lambda: print('LATER', gc.get_freeze_count() > 0))\n"
            "p.skip_final_collection = wrapped\n" + _cli(["--help"]))
    out = subprocess.run([sys.executable, "-c", _PROBE + code], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    lines = [ln.split()[0] + " " + ln.split()[-1] for ln in out.stdout.splitlines() if ln.startswith(("PROBE", "LATER"))]
    assert lines == ["LATER False", "PROBE True"]


def test_the_command_exits_as_before_when_a_nanobind_module_is_loaded() -> None:
    """OMPL's nanobind bindings (the planned pick-place mode) report objects alive at exit as leaks
    on stderr: with them loaded the collector is not frozen, and nothing is reported."""
    pytest.importorskip("ompl")
    code = "import ompl.base as ob, ompl.geometric as og\nspace = ob.RealVectorStateSpace(2)\n" + _cli(["--help"])
    assert _probe(code)[3] == "False"


def test_main_called_after_numpy_leaves_the_environment_alone() -> None:
    """A program (or a test) that loaded numpy and calls main() keeps its environment."""
    blas, omp, _, _ = _probe("import numpy\n" + _cli(["--help"]))
    assert (blas, omp) == ("None", "None")
