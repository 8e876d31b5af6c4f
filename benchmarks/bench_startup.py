"""Start-up of a fresh robocfg process: CLI commands, importing the pick-place runner, and the
time until a pick-place process's world is ready and its first episode is done.

Usage: python benchmarks/bench_startup.py [--runs 15] [--only help,run-help,...,first-episode,library-floor] [--json out.json]

Every row is a fresh process (``python -m robocfg`` with the interpreter running this script),
run in ``--root`` (default: this script's checkout; the current directory comes first on the
child's ``sys.path``, so ``--root`` picks the checkout measured), ``--runs`` times after one
warm-up run (file cache). Rows:

* ``help``: ``robocfg --help``; ``run-help``: ``robocfg run pick-place --help``;
* ``validate-task``: ``robocfg validate`` of the shipped ``pick_place.yaml`` (its robot too);
  ``validate-all``: ``robocfg validate`` (every built-in robot and task);
* ``import-runner``: ``python -c "import robocfg.runners.pick_place"``;
* ``run-1``: ``robocfg run pick-place -n 1 -q`` (the whole process, first episode included);
* ``first-episode``: a process using the per-episode API as a pool worker or Ray actor does
  (``robocfg.load_task`` → ``open_session`` → ``session.run(0)`` → ``session.run(1)``), timed from
  just before the spawn: *imports* (robocfg.engine and the task loader imported), *task* (loaded
  and checked), *world* (the world built: the **fixed start** a process pays before its first
  episode), *episode 0* done, and *episode 1* alone (what each further episode costs). The child
  pauses the garbage collector first as those workers do (:mod:`robocfg.collector`, which also
  installs the start-up code cache, :mod:`robocfg.startcache`, in ``ROBOCFG_CACHE_DIR``; the engine
  resumes it once the world is built; a checkout without that module, e.g. an older ``--root``,
  runs with its collector as it was) and runs with one math-library thread as they do (``OPENBLAS_NUM_THREADS``,
  ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS`` = 1, unless set in this environment: a pool's fork
  server sets them, Ray sets ``OMP_NUM_THREADS``); ``--math-threads default`` leaves the
  libraries their default (a thread per core each for numpy's and scipy's OpenBLAS).
* ``library-floor``: the same job without robocfg, the floor any tool on these libraries pays: a
  process that imports numpy, PyYAML, pydantic, pinocchio and pybullet (*imports*), then connects
  a DIRECT client without its renderer, loads the shipped task's robot URDF as the world does
  (inertia from the file, no visual shapes, self-collision) and builds its pinocchio model
  (*world*), timed from just before the spawn as ``first-episode`` is. ``first-episode: world``
  minus this row's *world* is what robocfg's own code adds to the fixed start (config loading and
  checks, its modules, the scene, the kinematic model's set-up, the reach check).

For each row: min / median / max wall time and the median CPU time of the child (user + sys:
what the wall time would be on an idle core). The machine's 1-minute load average is printed:
on a shared 2-core machine other processes inflate the wall times, so read the min and CPU
columns when the load is not ~0.

``--against OTHER`` measures a second checkout in the same session (before / after a change):
every sample of a row is taken in both, alternately, the order swapped each time, so both see the
same load; each row is printed for ``--root`` and then for OTHER with the median of the paired
CPU differences (OTHER − root).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

from robocfg.executors.worker_setup import MATH_THREAD_VARIABLES

ROOT = Path(__file__).resolve().parent.parent  # replaced by --root
ROBOCFG = [sys.executable, "-m", "robocfg"]

# row → (argv, goal in s or None)
CASES: dict[str, tuple[list[str], float | None]] = {
    "help": ([*ROBOCFG, "--help"], 0.3),
    "run-help": ([*ROBOCFG, "run", "pick-place", "--help"], 0.5),
    "validate-task": ([*ROBOCFG, "validate", "robocfg/data/tasks/pick_place.yaml"], 0.5),
    "validate-all": ([*ROBOCFG, "validate"], 1.5),
    "import-runner": ([sys.executable, "-c", "import robocfg.runners.pick_place"], None),
    "run-1": ([*ROBOCFG, "run", "pick-place", "-n", "1", "-q"], None),
}

# the first-episode child: prints wall-clock stamps (time.time(), comparable with the parent's)
# and its own CPU time at each mark, as one JSON line
_FIRST = """
import json, time
marks = {}
def mark(name):
    marks[name] = (time.time(), time.process_time())
try:
    from robocfg import collector
except ImportError:  # a checkout from before robocfg.collector (--root/--against an older one)
    pass
else:
    collector.pause()  # as a pool worker or Ray actor does first (robocfg.collector)
from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
mark("imports")
task = load_task(catalog.find("tasks", "pick_place"))
mark("task")
session = open_session(task, RunOptions(seed=0, episodes=2))
mark("world")
session.run(0)
mark("episode 0")
session.run(1)
mark("episode 1")
session.close()
print(json.dumps(marks))
"""
# the library-floor child: argv[1] is the robot URDF the shipped task's world loads
_FLOOR = """
import json, sys, time
marks = {}
def mark(name):
    marks[name] = (time.time(), time.process_time())
import numpy, yaml, pydantic, pinocchio, pybullet as p
mark("imports")
urdf = sys.argv[1]
c = p.connect(p.DIRECT)
p.unloadPlugin(p.loadPlugin("tinyRendererPlugin", physicsClientId=c), physicsClientId=c)
flags = p.URDF_USE_INERTIA_FROM_FILE | p.URDF_IGNORE_VISUAL_SHAPES | p.URDF_USE_SELF_COLLISION
p.loadURDF(urdf, useFixedBase=True, flags=flags | p.URDF_USE_SELF_COLLISION_EXCLUDE_ALL_PARENTS, physicsClientId=c)
with open(urdf) as f:
    pinocchio.buildModelFromXML(f.read())
mark("world")
print(json.dumps(marks))
"""
FLOOR_MARKS = ("imports", "world")
FIRST_MARKS = ("imports", "task", "world", "episode 0")
FIRST_GOAL = {"world": 0.5}  # the goal for the fixed start


def _set_root(root: Path) -> None:
    global ROOT
    ROOT = root


def _timed(argv: list[str], cwd: Path | None = None, env: dict[str, str] | None = None) -> tuple[float, float, str]:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(argv, cwd=cwd or ROOT, env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, out.stdout


def _row(label: str, wall: list[float], cpu: list[float], goal: float | None) -> dict:
    med = statistics.median(wall)
    ok = "" if goal is None else ("yes" if med <= goal else "NO")
    print(f"{label:<26}{min(wall):>8.3f}{med:>10.3f}{max(wall):>8.3f}{statistics.median(cpu):>8.3f}"
          f"{'' if goal is None else f'{goal:.2f}':>8}  {ok}")
    return {"row": label, "min_s": min(wall), "median_s": med, "max_s": max(wall),
            "cpu_median_s": statistics.median(cpu), "goal_s": goal}


def _worker_env(math_threads: str) -> dict[str, str] | None:
    """The first-episode child's environment: a pool worker's (one math thread unless the user set
    a count: robocfg.executors.worker_setup.single_threaded_env) or, ``default``, this one's."""
    if math_threads == "default" or any(v in os.environ for v in MATH_THREAD_VARIABLES):
        return None
    return dict(os.environ, **dict.fromkeys(MATH_THREAD_VARIABLES, "1"))


def _first_episode(runs: int, roots: list[Path], env: dict[str, str] | None = None) -> dict[Path, tuple[dict, dict]]:
    """root → (wall, CPU) samples of each mark, the roots taking turns (order swapped each run)."""
    argv = [sys.executable, "-c", _FIRST]
    names = (*FIRST_MARKS, "episode 1 alone")
    out: dict[Path, tuple[dict, dict]] = {r: ({m: [] for m in names}, {m: [] for m in names}) for r in roots}
    for r in roots:
        _timed(argv, r, env)  # warm-up
    for i in range(runs):
        for r in roots if i % 2 == 0 else roots[::-1]:
            wall, cpu = out[r]
            t0 = time.time()
            _, _, stdout = _timed(argv, r, env)
            marks = json.loads(stdout.strip().splitlines()[-1])
            for m in FIRST_MARKS:
                wall[m].append(marks[m][0] - t0)
                cpu[m].append(marks[m][1])
            wall["episode 1 alone"].append(marks["episode 1"][0] - marks["episode 0"][0])
            cpu["episode 1 alone"].append(marks["episode 1"][1] - marks["episode 0"][1])
    return out


def _task_urdf() -> str:
    """The robot URDF file the shipped pick-place task's world hands to PyBullet."""
    from robocfg.sim.quiet import quiet_import

    quiet_import()  # pybullet's build banner stays out of the table
    from robocfg.checks.task import load_task
    from robocfg.config import catalog
    from robocfg.sim.loading import prepared_urdf

    return str(prepared_urdf(load_task(catalog.find("tasks", "pick_place")).robots[0]))


def _floor(runs: int, env: dict[str, str] | None) -> dict[str, tuple[list, list]]:
    """mark → (wall, CPU) samples of the library-floor child (in this checkout's folder: it imports
    no robocfg, so every checkout has the same floor)."""
    argv = [sys.executable, "-c", _FLOOR, _task_urdf()]
    out: dict[str, tuple[list, list]] = {m: ([], []) for m in FLOOR_MARKS}
    _timed(argv, None, env)  # warm-up
    for _ in range(runs):
        t0 = time.time()
        _, _, stdout = _timed(argv, None, env)
        marks = json.loads(stdout.strip().splitlines()[-1])
        for m in FLOOR_MARKS:
            out[m][0].append(marks[m][0] - t0)
            out[m][1].append(marks[m][1])
    return out


def _samples(argv: list[str], runs: int, roots: list[Path]) -> dict[Path, tuple[list, list]]:
    out: dict[Path, tuple[list, list]] = {r: ([], []) for r in roots}
    for r in roots:
        _timed(argv, r)  # warm-up (file cache, bytecode)
    for i in range(runs):
        for r in roots if i % 2 == 0 else roots[::-1]:
            wall, cpu, _ = _timed(argv, r)
            out[r][0].append(wall)
            out[r][1].append(cpu)
    return out


def _rows(label: str, samples: dict[Path, tuple[list, list]], goal: float | None) -> list[dict]:
    roots = list(samples)
    rows = [_row(label, *samples[roots[0]], goal)]
    if len(roots) == 2:
        base_cpu, cpu = samples[roots[0]][1], samples[roots[1]][1]
        diff = statistics.median([b - a for a, b in zip(base_cpu, cpu, strict=True)])
        rows.append(_row(f"  vs --against ({diff:+.3f})", *samples[roots[1]], goal))
        rows[-1].update(row=f"{label} (against)", checkout=str(roots[1]), cpu_paired_diff_median_s=diff)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--only", default="", help="comma-separated rows (default: all), e.g. help,first-episode")
    ap.add_argument("--json", type=Path, default=None, help="write the rows here")
    ap.add_argument("--root", type=Path, default=ROOT, help="the checkout to measure (default: this one)")
    ap.add_argument("--against", type=Path, default=None,
                    help="a second checkout measured in the same session, alternating with --root")
    ap.add_argument("--math-threads", choices=("1", "default"), default="1",
                    help="first-episode child: one math-library thread as a pool worker or Ray actor runs "
                         "(default), or the libraries' default")
    args = ap.parse_args()
    _set_root(args.root.resolve())
    roots = [ROOT] + ([args.against.resolve()] if args.against is not None else [])
    only = [s for s in args.only.split(",") if s] or [*CASES, "first-episode", "library-floor"]
    unknown = set(only) - {*CASES, "first-episode", "library-floor"}
    if unknown:
        sys.exit(f"unknown rows: {', '.join(sorted(unknown))}")
    print(f"load average before: {os.getloadavg()[0]:.2f}   runs: {args.runs}   python: {sys.version.split()[0]}   "
          f"root: {ROOT}" + (f"   against: {roots[1]}" if len(roots) == 2 else "") +
          f"   first-episode math threads: {args.math_threads}")
    print(f"{'row':<26}{'min s':>8}{'median s':>10}{'max s':>8}{'CPU s':>8}{'goal s':>8}  ok")
    rows = []
    for label in only:
        if label == "first-episode":
            first = _first_episode(args.runs, roots, _worker_env(args.math_threads))
            for m in (*FIRST_MARKS, "episode 1 alone"):
                rows += _rows(f"first-episode: {m}", {r: (w[m], c[m]) for r, (w, c) in first.items()},
                              FIRST_GOAL.get(m))
            continue
        if label == "library-floor":
            for m, (wall, cpu) in _floor(args.runs, _worker_env(args.math_threads)).items():
                rows.append(_row(f"library floor: {m}", wall, cpu, None))
            continue
        argv, goal = CASES[label]
        rows += _rows(label, _samples(argv, args.runs, roots), goal)
    load = os.getloadavg()[0]
    print(f"load average after: {load:.2f}")
    if args.json is not None:
        args.json.write_text(json.dumps({"rows": rows, "runs": args.runs, "load_after": load}, indent=2) + "\n")


if __name__ == "__main__":
    main()
