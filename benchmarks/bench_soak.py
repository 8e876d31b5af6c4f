"""Soak: many pick-place episodes in one process — memory stays flat, and every failure (plus a
sample of successes) is reproduced exactly by the per-episode API in a fresh session.

    python benchmarks/bench_soak.py --episodes 2000 [--seed 0] [--task pick_place] [--robot NAME]
                                    [--warmup 100] [--check 5] [--json out.json]

One session (one world, restored before each episode) runs episodes 0 .. N−1 exactly as
``robocfg run pick-place -n N`` does. Memory: the peak resident set size (VmHWM) after the
warm-up episodes against the peak at the end (goal: growth < 5 %), with the current RSS sampled
along the way (its growth per episode after the warm-up is printed too). Reproduction: each failed episode, and ``--check`` successful ones spread over the
run, is run again alone with ``run_episode(EpisodeSpec(task, seed, k))`` in a new world; its record
must equal the batch's record field for field (goal: all equal).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path


def _status_kib(field: str) -> int:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise RuntimeError(f"/proc/self/status has no {field}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--task", default="pick_place")
    ap.add_argument("--robot", default=None)
    ap.add_argument("--warmup", type=int, default=100, help="episodes before the memory baseline is taken")
    ap.add_argument("--check", type=int, default=5, help="successful episodes also reproduced alone")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    warmup = min(args.warmup, max(1, args.episodes // 2))

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    import robocfg
    from robocfg.engine import EpisodeSpec, RunOptions, open_session, run_episode
    from robocfg.engine.spec import close_cached_session

    task = robocfg.load_task(args.task, robot=args.robot)
    options = RunOptions(seed=args.seed)
    records, trace = [], []
    t0 = time.perf_counter()
    rss_start = _status_kib("VmRSS")
    with open_session(task, options) as session:
        for k in range(args.episodes):
            records.append(session.run(k))
            if k + 1 == warmup:
                hwm_warm = _status_kib("VmHWM")
            if (k + 1) % max(1, args.episodes // 20) == 0 or k + 1 == args.episodes:
                trace.append((k + 1, _status_kib("VmRSS")))
                print(f"  {k + 1:>5} episodes  RSS {trace[-1][1] / 1024:7.1f} MiB  "
                      f"{time.perf_counter() - t0:7.1f} s", flush=True)
    wall = time.perf_counter() - t0
    hwm_end = _status_kib("VmHWM")
    growth = (hwm_end - hwm_warm) / hwm_warm
    after = [(k, v) for k, v in trace if k >= warmup]
    slope = ((after[-1][1] - after[0][1]) / (after[-1][0] - after[0][0])) if len(after) > 1 else 0.0  # KiB/episode

    failed = [r.index for r in records if not r.success]
    ok = [r.index for r in records if r.success]
    step = max(1, len(ok) // max(1, args.check))
    sample = ok[::step][:args.check] if args.check else []
    checked, mismatched = [], []
    for k in sorted(set(failed) | set(sample)):
        alone = run_episode(EpisodeSpec.of(task, k, options))
        close_cached_session()  # every check in a new world
        same = dataclasses.asdict(alone) == dataclasses.asdict(records[k])
        checked.append(k)
        if not same:
            mismatched.append(k)
    result = {
        "task": args.task, "robot": task.robots[0].config.name, "seed": args.seed, "episodes": args.episodes,
        "successes": len(ok), "failures": failed,
        "failure_reasons": sorted({f"{r.failed_phase}: {r.reason}" for r in records if not r.success}),
        "wall_s": round(wall, 1), "wall_per_episode_s": round(wall / args.episodes, 4),
        "rss_start_mib": round(rss_start / 1024, 1), "peak_rss_after_warmup_mib": round(hwm_warm / 1024, 1),
        "peak_rss_end_mib": round(hwm_end / 1024, 1), "peak_rss_growth": round(growth, 4), "warmup": warmup,
        "rss_trace_mib": [(k, round(v / 1024, 1)) for k, v in trace],
        "rss_growth_kib_per_episode_after_warmup": round(slope, 2),
        "reproduced_alone": checked, "mismatched": mismatched,
    }
    print(f"soak: {args.episodes} episodes of {args.task} ({result['robot']}), seed {args.seed}: "
          f"{len(ok)} placed, {len(failed)} failed, {wall:.0f} s ({result['wall_per_episode_s']:.3f} s/episode)")
    print(f"peak RSS after {warmup} episodes {hwm_warm / 1024:.1f} MiB, at the end {hwm_end / 1024:.1f} MiB: "
          f"growth {growth:+.2%} (goal < 5 %: {'met' if growth < 0.05 else 'NOT met'}); RSS after the warm-up "
          f"{slope:+.1f} KiB per episode")
    print(f"reproduced alone in a new world: {len(checked) - len(mismatched)}/{len(checked)} identical "
          f"(episodes {checked}; every failure among them: {len(failed)})")
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
