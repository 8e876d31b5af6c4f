"""Process time of every case of the bad-input corpus (tests/_corpus.py), each in its own process.

    python benchmarks/bench_corpus.py [--only PREFIX,...] [--limit N] [--json out.json]

Each case runs as ``python -m robocfg ARGS`` (interpreter start included, as a user sees it).
Prints the cases that did not give their expected exit code, any killed by a signal or printing
a traceback, then the median and slowest of two times per case: wall (what a user waits, which
grows with the machine's load) and CPU (user + system seconds of the child process, which does
not), with the 1-minute load average before and after, so a figure says what it was taken under.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests._corpus import all_cases, write  # noqa: E402


def _child_cpu() -> float:
    """User + system CPU seconds of all finished child processes so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _stats(rows: list[dict], key: str) -> str:
    vals = sorted(r[key] for r in rows)
    worst = max(rows, key=lambda r: r[key])
    return f"median {statistics.median(vals):.2f} s, max {vals[-1]:.2f} s ({worst['case']})"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", default="", help="Comma-separated case-name prefixes (default: every case).")
    ap.add_argument("--limit", type=int, default=0, help="Only the first N cases (0 = all).")
    ap.add_argument("--json", type=Path, default=None, help="Write the per-case times here.")
    args = ap.parse_args()
    prefixes = tuple(p for p in args.only.split(",") if p)
    cases = [c for c in all_cases() if not prefixes or c.name.startswith(prefixes)][: args.limit or None]
    rows = []
    load_before = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="robocfg-corpus-") as tmp:
        for k, case in enumerate(cases):
            folder = Path(tmp) / f"{k:03d}"
            argv = write(case, folder)
            cpu0, t0 = _child_cpu(), time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "robocfg", *argv], capture_output=True, text=True, cwd=ROOT)
            wall, cpu = time.perf_counter() - t0, _child_cpu() - cpu0
            out = proc.stdout + proc.stderr
            rows.append({"case": case.name, "exit": proc.returncode, "expected": case.exit, "wall_s": round(wall, 3),
                         "cpu_s": round(cpu, 3), "traceback": "Traceback" in out})
    load_after = os.getloadavg()[0]
    bad = [r for r in rows if r["exit"] != r["expected"] or r["traceback"]]
    print(f"{len(rows)} cases on {os.cpu_count()} CPUs, load average {load_before:.1f} before, {load_after:.1f} after: "
          f"{len(bad)} unexpected, {sum(r['exit'] < 0 for r in rows)} signals, {sum(r['traceback'] for r in rows)} tracebacks")
    print(f"  wall: {_stats(rows, 'wall_s')}")
    print(f"  CPU:  {_stats(rows, 'cpu_s')}")
    print(f"  over 2 s: {sum(r['wall_s'] > 2 for r in rows)} by wall, {sum(r['cpu_s'] > 2 for r in rows)} by CPU")
    for r in bad:
        print("unexpected:", r)
    if args.json:
        args.json.write_text(json.dumps({"load_before": load_before, "load_after": load_after, "cases": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
