"""For ``bench_scaling``: the pool's worker set-ups it compares (``--pool-variants``), the machine's
steal time over a run, and the table of what an episode costs its process at each worker count.

Variants (:class:`robocfg.executors.worker_setup.WorkerSetup`), each run as its own executor in
the same interleaved rounds (who goes first rotating), so one run compares them:

* ``single`` — executor ``pool``: what ``--workers`` does (one math-library thread per worker);
* ``default`` — ``pool-default``: the math libraries' own default, a thread per core in every
  worker (the pool before ``worker_setup``; emulated: the fork server has no math threads, the
  worker tells its libraries to use every core);
* ``pin`` — ``pool-pin``: single, and worker i bound to core i mod n;
* ``malloc`` — ``pool-malloc``: single, and glibc's mmap threshold fixed at 64 MiB and trimming at
  512 MiB (large temporaries stay on the heap: fewer page faults).

Per episode (medians over every episode of every round; the first episode of each worker, which
builds what is built lazily, counted too):

* ``proc ms`` — the worker process's CPU (every thread); ``main ms`` — the thread that ran the
  episode (``time.thread_time``); ``other`` — proc − main per episode (math-library or executor
  threads);
* ``wall ms`` — the episode's wall time; ``phys ms`` — its wall time inside ``stepSimulation``
  (with *had core* near 100 % these are CPU times too: whether a rise is the engine's or the
  Python around it);
* ``user ms`` / ``sys ms`` — the process's user and system CPU (``getrusage``);
* ``minflt`` — minor page faults (a page first touched: mapped memory, zeroed by the kernel);
  ``vcsw`` / ``ivcsw`` — voluntary (waited: I/O, a lock, a sleep) and involuntary (preempted:
  another runnable thread got the core) context switches;
* ``1st proc/main`` — the workers' first episodes, process vs main thread (math threads spinning
  show there);
* ``threads`` — the worker's threads when its world was built (median over workers); ``math`` —
  the most threads a math library loaded in it may use then (OpenBLAS's count: 1 = single);
* ``steal %`` — the machine's steal time over the run (``/proc/stat``: time a virtual CPU was
  ready but its host ran something else) in % of all CPUs' time; ``busy %`` — the machine's
  non-idle time over the run in % of all CPUs' time (every process, not only the workers).
"""

from __future__ import annotations

import statistics
from dataclasses import dataclass

VARIANTS = {"single": "pool", "default": "pool-default", "pin": "pool-pin", "malloc": "pool-malloc"}


def setup_of(kind: str):
    """The :class:`WorkerSetup` of pool executor ``kind`` (``pool``, ``pool-default``...)."""
    from robocfg.executors.worker_setup import WorkerSetup

    return {"pool": WorkerSetup(), "pool-default": WorkerSetup(math_threads=None),
            "pool-pin": WorkerSetup(pin=True), "pool-malloc": WorkerSetup(malloc=True)}[kind]


def pool_kinds(spec: str) -> list[str]:
    """``--pool-variants single,default`` → executor names; ``single`` (``pool``, the reference of
    the efficiencies and of Ray) always first."""
    names = [v.strip() for v in spec.split(",") if v.strip()]
    unknown = [v for v in names if v not in VARIANTS]
    if unknown:
        raise SystemExit(f"--pool-variants: unknown {unknown}; known: {', '.join(VARIANTS)}")
    return ["pool", *[VARIANTS[v] for v in names if v != "single"]]


@dataclass(frozen=True)
class CpuTimes:
    """The machine's CPU time (clock ticks, all CPUs) from ``/proc/stat``: total, idle (+ iowait),
    steal. Zeros where it cannot be read."""

    total: int = 0
    idle: int = 0
    steal: int = 0

    @classmethod
    def now(cls) -> CpuTimes:
        try:
            with open("/proc/stat") as f:
                fields = [int(x) for x in f.readline().split()[1:]]
        except (OSError, ValueError):
            return cls()
        # user nice system idle iowait irq softirq steal (guest, guest_nice are inside user, nice)
        return cls(sum(fields[:8]), fields[3] + fields[4], fields[7] if len(fields) > 7 else 0)

    def since(self, before: CpuTimes) -> tuple[float, float]:
        """(steal %, busy %) of all CPUs' time between ``before`` and this one (NaN: unknown)."""
        total = self.total - before.total
        if total <= 0:
            return float("nan"), float("nan")
        return 100 * (self.steal - before.steal) / total, 100 * (1 - (self.idle - before.idle) / total)


def _med(values: list[float]) -> float:
    v = [x for x in values if x == x]
    return statistics.median(v) if v else float("nan")


def usage_table(samples: list, kinds: list[str], counts: list[int]) -> list[dict]:
    """Print what an episode cost its process (see the module docstring) for each executor and
    worker count; return the rows as JSON-ready data."""
    print("\nWhat an episode cost its worker process (medians over episodes; steal, busy: medians over the rounds):")
    print(f"{'executor':<13}{'w':>3}{'proc ms':>8}{'main ms':>8}{'other':>6}{'wall ms':>8}{'phys ms':>8}"
          f"{'user ms':>8}{'sys ms':>7}{'minflt':>7}"
          f"{'vcsw':>6}{'ivcsw':>6}{'1st proc/main':>14}{'threads':>8}{'math':>5}{'steal %':>8}{'busy %':>7}")
    rows = []
    for kind in kinds:
        for w in counts:
            runs = [s for s in samples if s.executor == kind and s.workers == w]
            usage = [u for s in runs for u in s.usage if u is not None]
            if not runs:
                continue
            proc = [c for s in runs for c in s.episode_cpu]
            main = [c for s in runs for c in s.episode_thread_cpu]
            other = [p - m for s in runs for p, m in zip(s.episode_cpu, s.episode_thread_cpu, strict=True)]
            row = {"executor": kind, "workers": w, "proc_ms": 1e3 * _med(proc), "main_ms": 1e3 * _med(main),
                   "other_ms": 1e3 * _med(other),
                   "wall_ms": 1e3 * _med([c for s in runs for c in s.episode_wall]),
                   "physics_ms": 1e3 * _med([c for s in runs for c in s.episode_physics]),
                   "user_ms": 1e3 * _med([u.user for u in usage]), "sys_ms": 1e3 * _med([u.system for u in usage]),
                   "minflt": _med([u.minflt for u in usage]), "majflt": _med([u.majflt for u in usage]),
                   "nvcsw": _med([u.nvcsw for u in usage]), "nivcsw": _med([u.nivcsw for u in usage]),
                   "first_proc_ms": 1e3 * _med([s.first_cpu for s in runs]),
                   "first_main_ms": 1e3 * _med([s.first_thread_cpu for s in runs]),
                   "threads": _med([t for s in runs for t in s.threads]),
                   "math_threads": _med([t for s in runs for t in s.math_threads]),
                   "steal_pct": [s.steal_pct for s in runs], "busy_pct": [s.busy_pct for s in runs]}
            rows.append(row)
            print(f"{kind:<13}{w:>3}{row['proc_ms']:>8.1f}{row['main_ms']:>8.1f}{row['other_ms']:>6.1f}"
                  f"{row['wall_ms']:>8.1f}{row['physics_ms']:>8.1f}"
                  f"{row['user_ms']:>8.1f}{row['sys_ms']:>7.1f}{row['minflt']:>7.0f}{row['nvcsw']:>6.0f}{row['nivcsw']:>6.0f}"
                  f"{row['first_proc_ms']:>8.0f}/{row['first_main_ms']:<5.0f}{row['threads']:>8.0f}{row['math_threads']:>5.0f}"
                  f"{_med(row['steal_pct']):>8.2f}{_med(row['busy_pct']):>7.1f}")
    print("(proc: the worker process's CPU; main: the episode's thread; other: proc − main; wall: the episode's wall"
          " time; phys: its wall time inside stepSimulation; user/sys: the process's"
          " user and system CPU; minflt: minor page faults; vcsw/ivcsw: voluntary/involuntary context switches;"
          " 1st: each worker's first episode; threads: the worker's threads once its world was built; math: its math"
          " libraries' thread count then;"
          " steal/busy: the machine's steal and non-idle time over the run, % of all CPUs)")
    return rows


def variant_table(samples: list, kinds: list[str], counts: list[int], rounds: int) -> list[dict]:
    """Print, for each pool variant, its efficiency (steady ep/s at w ÷ w × its own at 1, per round)
    and its steady ep/s and main-thread CPU per episode ÷ those of ``pool`` in the same round
    (paired); return them as JSON-ready data."""
    variants = [k for k in kinds if k != "pool"]
    if not variants:
        return []
    by = {(s.executor, s.workers, s.round): s for s in samples}
    print("\nPool variants, paired with `pool` round by round (median [min–max] over the rounds):")
    print(f"{'variant':<13}{'w':>3}  {'efficiency':<22}{'its ÷ pool efficiency':<24}{'steady ÷ pool':<22}"
          f"{'main cpu ÷ pool':<22}")
    out = []
    for kind in ["pool", *variants]:
        for w in counts:
            eff, vs_eff, vs, vs_cpu = [], [], [], []
            for r in range(rounds):
                a, a1, p, p1 = by.get((kind, w, r)), by.get((kind, 1, r)), by.get(("pool", w, r)), by.get(("pool", 1, r))
                if a is not None and a1 is not None:
                    eff.append(a.eps / (w * a1.eps))
                    if p is not None and p1 is not None:
                        vs_eff.append(eff[-1] / (p.eps / (w * p1.eps)))
                if a is not None and p is not None and a.episode_thread_cpu and p.episode_thread_cpu:
                    vs.append(a.eps / p.eps)
                    vs_cpu.append(statistics.median(a.episode_thread_cpu) / statistics.median(p.episode_thread_cpu))
            if kind == "pool":  # the reference itself
                vs_eff, vs, vs_cpu = [], [], []
            print(f"{kind:<13}{w:>3}  {_spread(eff):<22}{_spread(vs_eff):<24}{_spread(vs):<22}{_spread(vs_cpu):<22}")
            out.append({"executor": kind, "workers": w, "efficiency": eff, "efficiency_over_pool": vs_eff,
                        "steady_over_pool": vs, "main_cpu_over_pool": vs_cpu})
    print("(efficiency: the variant's own, against its own 1-worker run of the round; steady ÷ pool: > 1 = the variant"
          " ran more episodes per second; main cpu ÷ pool: the median main-thread CPU per episode, < 1 = cheaper)")
    return out


def _spread(values: list[float]) -> str:
    v = [x for x in values if x == x]
    if not v:
        return "-"
    med = statistics.median(v)
    return f"{med:.2f}" if len(v) == 1 else f"{med:.2f} [{min(v):.2f}–{max(v):.2f}]"
