"""The IK queries of pick-place episodes, recorded and replayed: LM iterations per call site, CPU a
solve in the episode and replayed, and, with ``--base``, the same queries answered by an older
checkout's LM solver, answer for answer and in paired CPU.

    python benchmarks/bench_ik_queries.py --episodes 10 [--task pick_place] [--base /tmp/old] [--rounds 20]

Episodes 1..N of one session (seed ``--seed``; episode 0 warms up) run with ``KinematicModel.ik``
wrapped: each outermost call is recorded (target, seed, frame, budget, the solver's iteration cap),
with its answer, its iterations and its CPU (``time.thread_time``) in the episode, and a call site
read from the stack: ``line end`` / ``line cut`` (a straight line's IK at fraction 1 / below 1,
``robocfg.motion.straight_line``), else the first function outside the kinematics and the mover's
IK helpers (``_leg``: the grasp choice's reach checks; ``_free_move``: a joint-space move...).
The queries are then replayed ``--rounds`` times on the same model, warm (hot caches: a lower bound
of the in-episode cost), and each replayed answer must equal the recorded one bit for bit (the
solver is deterministic with an iteration cap). ``--base DIR`` (``git archive <commit> robocfg | tar
-x -C DIR``) loads DIR's ``kinematics/ik/lm.py`` and ``common.py`` under other module names and
answers the same queries with its ``LMSolver`` (bound to the same model, same settings): how many
answers are bit-identical, and CPU a solve of both, rounds alternating which goes first.
Queries that passed their own ``rng`` are not replayed (their generator's state is gone).
"""

from __future__ import annotations

import argparse
import collections
import dataclasses
import statistics as st
import sys
import time
import types
from pathlib import Path
from typing import Any

import numpy as np


@dataclasses.dataclass
class Query:
    model: Any  # the KinematicModel asked
    args: tuple  # (target, seed_q, frame, backend, time_budget, position_only)
    max_total_iter: int | None
    site: str
    cpu: float  # s, in the episode
    q: np.ndarray
    iterations: int
    residuals: tuple[float, float]


def _site() -> str:
    f = sys._getframe(2)
    while f is not None:
        name, path = f.f_code.co_name, f.f_code.co_filename
        if path.endswith("straight_line.py") and name == "solve" and "s" in f.f_locals:
            return "line end" if f.f_locals["s"] == 1.0 else "line cut"
        if "kinematics" not in path and not (path.endswith("moves.py") and name in ("ik", "solve", "<lambda>")):
            return name
        f = f.f_back
    return "?"


def _old_solver_class(base: Path) -> Any:
    """``LMSolver`` of ``base``'s lm.py, importing ``base``'s common.py, registered nowhere."""
    def load(name: str, path: Path, edit: Any = lambda s: s) -> types.ModuleType:
        mod = types.ModuleType(name)
        mod.__file__ = str(path)
        sys.modules[name] = mod
        exec(compile(edit(path.read_text()), str(path), "exec"), mod.__dict__)
        return mod

    ik = base / "robocfg" / "kinematics" / "ik"
    load("_base_ik_common", ik / "common.py")
    lm = load("_base_ik_lm", ik / "lm.py", lambda s: s.replace("from robocfg.kinematics.ik.common import",
                                                                "from _base_ik_common import").replace('@register("lm")', ""))
    return lm.LMSolver


def _replay(queries: list[Query], solver_of: Any) -> tuple[float, list[Any]]:
    """(thread CPU s, answers) of one pass over ``queries`` through ``KinematicModel.ik``, each with
    ``solver_of(query)`` as its model's LM solver."""
    clock, out = time.thread_time, []
    c0 = clock()
    for qy in queries:
        qy.model._solvers["lm"] = solver_of(qy)
        out.append(qy.model.ik(*qy.args))
    return clock() - c0, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=10)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=10, help="replays of all queries (per version)")
    ap.add_argument("--base", type=Path, default=None, help="directory with an older robocfg/ to compare with")
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.engine import RunOptions, open_session
    from robocfg.kinematics.model import KinematicModel

    t = load_task(catalog.find("tasks", args.task))
    task = dataclasses.replace(t, config=t.config.model_copy(update={"cameras": []}))
    queries: list[Query] = []
    skipped, depth, recording = [0], [0], [False]
    ik = KinematicModel.ik

    def recorded(self: Any, target: Any, seed_q: Any = None, frame: str = "tcp", backend: str | None = None,
                 time_budget: float = 0.02, position_only: bool = False, rng: Any = None) -> Any:
        if depth[0] or not recording[0]:
            return ik(self, target, seed_q, frame, backend, time_budget, position_only, rng)
        depth[0] += 1
        site, cap = _site(), getattr(self.solver(backend), "max_total_iter", None)
        c0 = time.thread_time()
        try:
            res = ik(self, target, seed_q, frame, backend, time_budget, position_only, rng)
        finally:
            depth[0] -= 1
        cpu = time.thread_time() - c0
        if rng is not None or (backend or self.default_backend) != "lm":
            skipped[0] += 1
        else:
            seed = None if seed_q is None else np.array(seed_q, dtype=float)
            queries.append(Query(self, (np.array(target, dtype=float), seed, frame, backend, time_budget, position_only),
                                 cap, site, cpu, res.q.copy(), res.iterations, (res.pos_err, res.rot_err)))
        return res

    KinematicModel.ik = recorded  # type: ignore[method-assign]
    with open_session(task, RunOptions(seed=args.seed)) as session:
        session.run(0)
        recording[0] = True
        for k in range(1, args.episodes + 1):
            session.run(k)
    KinematicModel.ik = ik  # type: ignore[method-assign]

    print(f"{args.task}, seed {args.seed}, episodes 1..{args.episodes}: {len(queries)} LM queries "
          f"({len(queries) / args.episodes:.1f} an episode; {skipped[0]} with their own rng or another backend, not replayed)")
    by_site: dict[str, list[Query]] = collections.defaultdict(list)
    for qy in queries:
        by_site[qy.site].append(qy)
    print(f"{'call site':<22} {'solves':>6} {'iterations':>10}  {'in-episode CPU us a solve':>25}  histogram (iterations: solves)")
    for site, qs in sorted(by_site.items(), key=lambda kv: -sum(q.cpu for q in kv[1])):
        hist = collections.Counter(q.iterations for q in qs)
        print(f"{site:<22} {len(qs):>6} {st.mean(q.iterations for q in qs):>10.2f}  {st.median(q.cpu for q in qs) * 1e6:>12.0f} median "
              f"{st.mean(q.cpu for q in qs) * 1e6:>5.0f} mean  " + ", ".join(f"{i}: {n}" for i, n in sorted(hist.items())))

    todays = {id(qy.model): qy.model.solver("lm") for qy in queries}
    for qy in queries:  # every model's solver with the cap it had (bound_ik_by_iterations)
        todays[id(qy.model)].max_total_iter = qy.max_total_iter
    versions: dict[str, Any] = {"today": lambda qy: todays[id(qy.model)]}
    if args.base is not None:
        old_cls, olds = _old_solver_class(args.base), {}

        def old_of(qy: Query) -> Any:
            key = (id(qy.model), qy.max_total_iter)
            if key not in olds:
                olds[key] = old_cls(qy.model)
                olds[key].max_total_iter = qy.max_total_iter
            return olds[key]
        versions["base"] = old_of
    cpu: dict[str, list[float]] = {v: [] for v in versions}
    for r in range(args.rounds):
        for v in (list(versions) if r % 2 == 0 else list(versions)[::-1]):
            s, answers = _replay(queries, versions[v])
            cpu[v].append(s / max(1, len(queries)))
            same = sum(a.q.tobytes() == qy.q.tobytes() and a.iterations == qy.iterations
                       and (a.pos_err, a.rot_err) == qy.residuals for a, qy in zip(answers, queries, strict=True))
            if r == 0:
                print(f"{v}: {same} of {len(queries)} answers bit-identical to the episodes' "
                      f"({sum(a.iterations for a in answers) / max(1, len(answers)):.2f} iterations a solve)")
    for qy in queries:
        qy.model._solvers["lm"] = todays[id(qy.model)]
    for v, xs in cpu.items():
        print(f"replayed warm, {v}: {st.median(xs) * 1e6:.1f} us a solve (median of {args.rounds} rounds, min {min(xs) * 1e6:.1f})")
    if "base" in cpu:
        d = [b - a for a, b in zip(cpu["today"], cpu["base"], strict=True)]
        print(f"paired (base - today): {st.median(d) * 1e6:.1f} us a solve (min {min(d) * 1e6:.1f}, max {max(d) * 1e6:.1f})")


if __name__ == "__main__":
    main()
