"""Support-height ray casts of pick-place episodes: casts per query and CPU per query.

    python benchmarks/bench_support_casts.py [--task pick_place] [--episodes 4] [--seed 0]

Runs ``--episodes`` episodes of a pick-place task in one session (cameras off) and wraps
``_StateMachine._support_height`` and ``pybullet.rayTest``: for each query of an episode (in
order: the object's rest at set-up, the grasp's lying object, the place point before the carry,
the placed check) the number of ``rayTest`` calls it made and its main-thread CPU in place (µs,
cold caches after physics steps included). Prints one line per query position, means over
episodes, and the casts an episode. Run it with an older checkout first on ``PYTHONPATH`` for the
"before" figures. Episodes that end before the placed check have fewer queries; they are left
out of the means.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics as st
import time
from typing import Any


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--episodes", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import pybullet

    import robocfg.runners.pick_place_machine as ppm
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.engine import RunOptions, open_session

    task = load_task(catalog.find("tasks", args.task))
    task = dataclasses.replace(task, config=task.config.model_copy(update={"cameras": []}))
    casts = [0]
    ray = pybullet.rayTest

    def counted(*a: Any, **k: Any) -> Any:
        casts[0] += 1
        return ray(*a, **k)

    queries: list[tuple[int, float]] = []  # (casts, CPU s) of this episode's queries
    support = ppm._StateMachine._support_height

    def wrapped(self: Any, *a: Any, **k: Any) -> float:
        casts[0] = 0
        t0 = time.thread_time()
        z = support(self, *a, **k)
        queries.append((casts[0], time.thread_time() - t0))
        return z

    pybullet.rayTest = counted
    ppm._StateMachine._support_height = wrapped  # type: ignore[method-assign]
    episodes: list[list[tuple[int, float]]] = []
    with open_session(task, RunOptions(seed=args.seed)) as session:
        for k in range(args.episodes):
            queries.clear()
            session.run(k)
            episodes.append(list(queries))
    full = [e for e in episodes if len(e) == 4]
    print(f"{args.task}, seed {args.seed}: {len(full)} of {len(episodes)} episodes with 4 queries")
    for i in range(4):
        if full:
            print(f"  query {i}: casts {st.mean(e[i][0] for e in full):.2f}, CPU {st.mean(e[i][1] for e in full) * 1e6:.0f} us")
    if full:
        print(f"  casts an episode {st.mean(sum(q[0] for q in e) for e in full):.2f}, CPU in the queries "
              f"{st.mean(sum(q[1] for q in e) for e in full) * 1e3:.3f} ms an episode")


if __name__ == "__main__":
    main()
