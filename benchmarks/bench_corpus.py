"""Wall time of every case of the bad-input corpus (tests/_corpus.py), each in its own process.

    python benchmarks/bench_corpus.py [--limit N] [--json out.json]

Each case runs as ``python -m robocfg ARGS`` (interpreter start included, as a user sees it);
prints the cases that did not give their expected exit code, any killed by a signal or printing
a traceback, and the median and slowest wall times.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tests._corpus import all_cases, write  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=0, help="Only the first N cases (0 = all).")
    ap.add_argument("--json", type=Path, default=None, help="Write the per-case times here.")
    args = ap.parse_args()
    cases = all_cases()[: args.limit or None]
    rows = []
    with tempfile.TemporaryDirectory(prefix="robocfg-corpus-") as tmp:
        for k, case in enumerate(cases):
            folder = Path(tmp) / f"{k:03d}"
            argv = write(case, folder)
            t0 = time.perf_counter()
            proc = subprocess.run([sys.executable, "-m", "robocfg", *argv], capture_output=True, text=True, cwd=ROOT)
            wall = time.perf_counter() - t0
            out = proc.stdout + proc.stderr
            rows.append({"case": case.name, "exit": proc.returncode, "expected": case.exit, "wall_s": round(wall, 3),
                         "traceback": "Traceback" in out})
    bad = [r for r in rows if r["exit"] != r["expected"] or r["traceback"]]
    walls = sorted(r["wall_s"] for r in rows)
    print(f"{len(rows)} cases: {len(bad)} unexpected, {sum(r['exit'] < 0 for r in rows)} signals, "
          f"{sum(r['traceback'] for r in rows)} tracebacks; wall median {statistics.median(walls):.2f} s, "
          f"max {walls[-1]:.2f} s ({max(rows, key=lambda r: r['wall_s'])['case']})")
    for r in bad:
        print("unexpected:", r)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
