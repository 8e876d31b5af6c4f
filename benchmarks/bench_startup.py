"""Whole-process wall time of `robocfg --help` and `robocfg validate` (all built-ins).

Usage: python benchmarks/bench_startup.py [--runs 15]

Each command runs as a fresh process (the installed `robocfg` console script), ``--runs`` times
after one warm-up run (file cache); prints min / median / max wall time, the median CPU time
(user + sys of the child: what the wall time would be on an idle core) and the goal. The
machine's 1-minute load average is printed too: other processes on a 2-core machine inflate
the wall times, so look at the min and CPU columns when the load is not ~0.
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

CASES = [("robocfg --help", ["--help"], 0.3), ("robocfg validate", ["validate"], 1.5)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=15)
    args = ap.parse_args()
    exe = shutil.which("robocfg", path=str(Path(sys.executable).parent)) or shutil.which("robocfg")
    if exe is None:
        sys.exit("robocfg is not installed in this environment")
    root = Path(__file__).resolve().parent.parent
    print(f"load average before: {os.getloadavg()[0]:.2f}   runs: {args.runs}   cwd: {root}")
    print(f"{'command':<22}{'min s':>8}{'median s':>10}{'max s':>8}{'CPU s':>8}{'goal s':>8}  ok")
    for label, argv, goal in CASES:
        subprocess.run([exe, *argv], cwd=root, capture_output=True, check=True)  # warm-up
        times, cpu = [], []
        for _ in range(args.runs):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([exe, *argv], cwd=root, capture_output=True, check=True)
            times.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
        med = statistics.median(times)
        print(f"{label:<22}{min(times):>8.3f}{med:>10.3f}{max(times):>8.3f}{statistics.median(cpu):>8.3f}{goal:>8.2f}"
              f"  {'yes' if med < goal else 'NO'}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
