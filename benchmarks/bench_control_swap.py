"""Paired, interleaved CPU cost of a code change to robocfg's own per-episode work, in one process:
episode k runs twice in the same session, once with today's functions and once with some of them
swapped for an older checkout's, in an order that alternates with k.

    python benchmarks/bench_control_swap.py --base /tmp/old --swap robocfg.motion.moves:ArmMover.converge,... [--episodes 20]

``--base`` is a directory holding an older ``robocfg/`` (``git archive <commit> robocfg | tar -x -C /tmp/old``).
Each ``--swap`` entry ``module:Qualified.name`` takes that function's definition from the base's
file, compiled among today's module's names with the base module's imports and constants (see
``_base_function``: the older body, today's everything else), and puts it in place of today's for
the "old" runs (all entries together); ``target=source`` takes the base's ``source`` (another
``module:name``) for today's ``target``, e.g. a function as another module imported it. Both versions must simulate the same thing (check with ``physics_hashes.py``):
the script checks that each pair of runs took the same physics steps and ended with the same
report record.

Per episode it reads the main thread's CPU (``time.thread_time``) and the CPU inside
``stepSimulation`` (one timer a step, the same in both runs), and reports robocfg's own work
(episode − physics) of each version: medians over episodes, and the median of the paired
differences (old − new) with its spread. On a shared machine the load changes within seconds;
pairing the same episode back to back, alternating which runs first, cancels most of it.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import statistics as st
import time
from pathlib import Path
from typing import Any


def _base_function(base: Path, module: str, qual: str) -> Any:
    """The function ``qual`` (``name`` or ``Class.name``) as the base's ``module`` defines it,
    compiled in today's module's namespace overlaid with the base module's imports and simple
    top-level assignments (its constants and aliases): the older body with today's everything
    else, without executing the older module (whose registrations would clash with today's)."""
    import __future__

    import ast

    path = base / Path(*module.split(".")).with_suffix(".py")
    tree = ast.parse(path.read_text(), str(path))
    namespace = dict(vars(importlib.import_module(module)))
    header = [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom, ast.Assign, ast.AnnAssign))
              and not (isinstance(n, ast.ImportFrom) and n.module == "__future__")]
    flags = __future__.annotations.compiler_flag
    exec(compile(ast.Module(body=header, type_ignores=[]), str(path), "exec", flags=flags, dont_inherit=True), namespace)
    body: list[ast.stmt] = tree.body
    *owners, name = qual.split(".")
    for owner in owners:
        body = next(n for n in body if isinstance(n, ast.ClassDef) and n.name == owner).body
    fn = next(n for n in body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.name == name)
    exec(compile(ast.Module(body=[fn], type_ignores=[]), str(path), "exec", flags=flags, dont_inherit=True), namespace)
    return namespace[name]


def _resolve(root: Any, qual: str) -> tuple[Any, str]:
    *owners, attr = qual.split(".")
    holder = root
    for o in owners:
        holder = getattr(holder, o)
    return holder, attr


class Swap:
    """Today's and the base's objects for each ``module:qual`` entry; ``use(old)`` installs one set."""

    def __init__(self, base: Path, entries: list[str]) -> None:
        self.items: list[tuple[Any, str, Any, Any]] = []  # (holder, attribute, today's, base's)
        for entry in entries:
            target, _, source = entry.partition("=")
            module, qual = target.split(":")
            src_module, src_qual = source.split(":") if source else (module, qual)
            holder, attr = _resolve(importlib.import_module(module), qual)
            self.items.append((holder, attr, vars(holder).get(attr), _base_function(base, src_module, src_qual)))
        # a base function that calls another swapped function by a module-level name (imported or
        # its own module's) calls the base's version of it: the base's functions work together
        for *_, before in self.items:
            names = before.__globals__
            for name, value in list(names.items()):
                for _, _, today, other in self.items:
                    if today is not None and value is today:
                        names[name] = other

    def use(self, old: bool) -> None:
        for holder, attr, today, before in self.items:
            f = before if old else today
            if f is None:
                if attr in vars(holder):
                    delattr(holder, attr)
            else:
                setattr(holder, attr, f)


def _task(name: str):
    from robocfg.checks import load_task
    from robocfg.config import catalog

    t = load_task(catalog.find("tasks", name))
    return dataclasses.replace(t, config=t.config.model_copy(update={"cameras": []}))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", required=True, type=Path, help="directory with the older robocfg/")
    ap.add_argument("--swap", required=True, help="comma-separated module:Qualified.name entries")
    ap.add_argument("--time", default="", help="comma-separated module:Qualified.name entries timed inclusively "
                    "(outermost calls only) in both versions: the changed code's own CPU, with less noise")
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import pybullet

    from robocfg.engine import RunOptions, open_session

    swap = Swap(args.base, [e for e in args.swap.split(",") if e])
    physics = [0.0]
    step = pybullet.stepSimulation
    clock = time.thread_time

    def timed_step(*a: Any, **k: Any) -> Any:
        t0 = clock()
        try:
            return step(*a, **k)
        finally:
            physics[0] += clock() - t0

    pybullet.stepSimulation = timed_step
    inside = [0.0, 0]  # CPU s in the --time functions, nesting depth

    def timed(f: Any) -> Any:
        def wrapper(*a: Any, **k: Any) -> Any:
            if inside[1]:
                return f(*a, **k)
            inside[1] = 1
            t0 = clock()
            try:
                return f(*a, **k)
            finally:
                inside[0] += clock() - t0
                inside[1] = 0
        return wrapper

    for entry in [e for e in args.time.split(",") if e]:  # today's and the base's alike (Swap wraps its copies)
        module, qual = entry.split(":")
        holder, attr = _resolve(importlib.import_module(module), qual)
        for item in swap.items:
            if item[0] is holder and item[1] == attr:
                swap.items[swap.items.index(item)] = (holder, attr, timed(item[2]), timed(item[3]))
                break
        else:
            setattr(holder, attr, timed(getattr(holder, attr)))
    own: dict[str, list[float]] = {"old": [], "new": []}
    changed: dict[str, list[float]] = {"old": [], "new": []}
    phys: dict[str, list[float]] = {"old": [], "new": []}
    with open_session(_task(args.task), RunOptions(seed=args.seed)) as session:
        for version in ("old", "new"):  # warm both
            swap.use(version == "old")
            session.run(0)
        for k in range(1, args.episodes + 1):
            records = {}
            for version in (("old", "new") if k % 2 else ("new", "old")):
                swap.use(version == "old")
                physics[0] = inside[0] = 0.0
                c0 = clock()
                records[version] = session.run(k)
                cpu = clock() - c0
                own[version].append(cpu - physics[0])
                changed[version].append(inside[0])
                phys[version].append(physics[0])
            a, b = records["old"], records["new"]
            if getattr(a, "steps", None) != getattr(b, "steps", None) or a != b:
                raise SystemExit(f"episode {k}: the two versions did not simulate the same thing ({a} vs {b})")
    swap.use(False)
    diffs = [o - n for o, n in zip(own["old"], own["new"], strict=True)]
    q = st.quantiles(diffs, n=4) if len(diffs) >= 2 else [diffs[0]] * 3
    med_phys = st.median(phys["new"] + phys["old"])
    res = {"task": args.task, "episodes": args.episodes, "swap": args.swap.split(","),
           "own_old_ms": round(st.median(own["old"]) * 1e3, 3), "own_new_ms": round(st.median(own["new"]) * 1e3, 3),
           "physics_ms": round(med_phys * 1e3, 2),
           "saved_ms_median": round(st.median(diffs) * 1e3, 3), "saved_ms_quartiles": [round(v * 1e3, 3) for v in (q[0], q[2])],
           "saved_share_of_physics": round(st.median(diffs) / med_phys, 4)}
    print(f"{args.task}, {args.episodes} episode pairs: own work {res['own_old_ms']:.2f} ms (old) vs "
          f"{res['own_new_ms']:.2f} ms (new) an episode (main-thread CPU outside stepSimulation, medians; physics "
          f"{res['physics_ms']:.1f} ms); paired saving {res['saved_ms_median']:.2f} ms (quartiles "
          f"{res['saved_ms_quartiles'][0]:.2f} .. {res['saved_ms_quartiles'][1]:.2f}), "
          f"{res['saved_share_of_physics']:.2%} of physics")
    if args.time:
        cdiff = [o - n for o, n in zip(changed["old"], changed["new"], strict=True)]
        cq = st.quantiles(cdiff, n=4) if len(cdiff) >= 2 else [cdiff[0]] * 3
        res |= {"timed_old_ms": round(st.median(changed["old"]) * 1e3, 3), "timed_new_ms": round(st.median(changed["new"]) * 1e3, 3),
                "timed_saved_ms_median": round(st.median(cdiff) * 1e3, 3),
                "timed_saved_ms_quartiles": [round(cq[0] * 1e3, 3), round(cq[2] * 1e3, 3)]}
        print(f"  inside the --time functions: {res['timed_old_ms']:.3f} ms (old) vs {res['timed_new_ms']:.3f} ms (new) an "
              f"episode; paired saving {res['timed_saved_ms_median']:.3f} ms (quartiles {res['timed_saved_ms_quartiles'][0]:.3f} .. "
              f"{res['timed_saved_ms_quartiles'][1]:.3f})")
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
