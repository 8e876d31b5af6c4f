"""What Ray itself costs around robocfg's batches: idle CPU of a local Ray, and one actor call's round trip.

    python benchmarks/bench_ray_overhead.py [--idle 20] [--calls 300]

Starts a local Ray as ``--executor ray`` does (``robocfg.executors.ray_pool.init_ray``, 2 CPUs),
one actor, and measures with psutil over every process under this one (raylet, GCS, agents, idle
and actor workers, this driver): (1) their CPU time over ``--idle`` seconds with nothing to do;
(2) the wall time and the CPU time of all of them per call of ``--calls`` sequential actor calls
that send back a real pick-place ``BatchDone`` (one episode's record), which is what a batch of
one episode costs on top of the episode. Also prints the pickled sizes of a recipe and a
``BatchDone``.
"""

from __future__ import annotations

import argparse
import pickle
import time


def tree_cpu() -> dict[int, tuple[str, float]]:
    """pid → (name, CPU s) of this process and every process under it."""
    import psutil

    me = psutil.Process()
    out = {}
    for p in [me, *me.children(recursive=True)]:
        try:
            t = p.cpu_times()
            out[p.pid] = (p.name(), t.user + t.system)
        except psutil.Error:
            continue
    return out


def since(before: dict[int, tuple[str, float]], after: dict[int, tuple[str, float]]) -> dict[int, tuple[str, float]]:
    return {pid: (name, cpu - before.get(pid, (name, 0.0))[1]) for pid, (name, cpu) in after.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--idle", type=float, default=20.0, help="seconds of idle Ray measured")
    ap.add_argument("--calls", type=int, default=300)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import os

    import ray

    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.engine import RunOptions
    from robocfg.executors.ray_pool import init_ray
    from robocfg.executors.recipe import EngineRecipe
    from robocfg.executors.session import Batch, run_batch

    recipe = EngineRecipe.of(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=0, episodes=1))
    session = recipe.open()
    done = run_batch(session, None, Batch(0, (0,)))
    session.close()
    print(f"pickled: recipe {len(pickle.dumps(recipe))} B, BatchDone of one episode {len(pickle.dumps(done))} B")
    print(f"load average: {os.getloadavg()[0]:.2f}")

    init_ray(ray, num_cpus=2)

    @ray.remote(num_cpus=1)
    class Echo:
        def back(self, x):
            return x

    actor = Echo.remote()  # type: ignore[attr-defined]
    ray.get(actor.back.remote(1))
    time.sleep(2.0)
    t0, w0 = tree_cpu(), time.perf_counter()
    time.sleep(args.idle)
    idle = since(t0, tree_cpu())
    dt = time.perf_counter() - w0
    total = sum(c for _, c in idle.values())
    top = sorted(((n, c) for n, c in idle.values()), key=lambda x: -x[1])[:8]
    print(f"idle over {dt:.0f} s: {total:.2f} s CPU in all = {100 * total / dt:.1f} % of one core; "
          + ", ".join(f"{n} {100 * c / dt:.1f} %" for n, c in top))
    t0, w0 = tree_cpu(), time.perf_counter()
    for _ in range(args.calls):
        ray.get(actor.back.remote(done))
    wall = time.perf_counter() - w0
    cpu = sum(c for _, c in since(t0, tree_cpu()).values())
    print(f"actor call returning a BatchDone: {1e3 * wall / args.calls:.2f} ms wall, "
          f"{1e3 * cpu / args.calls:.2f} ms CPU over every process, per call ({args.calls} calls)")
    print(f"load average: {os.getloadavg()[0]:.2f}")
    ray.shutdown()


if __name__ == "__main__":
    main()
