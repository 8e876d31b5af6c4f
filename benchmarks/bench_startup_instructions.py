"""Instructions of a fresh process's fixed start, counted by callgrind (deterministic whatever the
machine's load): the path of ``bench_startup.py``'s first-episode child (the collector paused as
a pool worker or Ray actor does, the shipped ``pick_place`` task loaded and checked, its session
opened: the world built), leaving with ``os._exit`` right there; optionally ``robocfg validate``
of one task or of everything (whole processes).

Usage: python benchmarks/bench_startup_instructions.py [--root CHECKOUT ...] [--rows world,validate-task,validate-all]
       [--env NAME=VALUE ...] [--runs 1]

Each ``--root`` (default: this script's checkout) is measured with ``--env`` added to the
environment (e.g. ``ROBOCFG_NO_START_CACHE=1`` to measure the same code without the start-up
code cache). One warm-up run per row and checkout fills robocfg's cache folder
(``ROBOCFG_CACHE_DIR``: a fresh temporary folder per checkout unless set) and the bytecode cache
(``PYTHONPYCACHEPREFIX``, a temporary folder unless set), so the counts are a warm start's. Fixed:
``PYTHONHASHSEED=0``, one math-library thread, ``PYTHONDONTWRITEBYTECODE`` unset. valgrind must
be installed; each run takes ≈ 1 min on the 2-core laptop.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

_WORLD = """
import os
try:
    from robocfg import collector
except ImportError:
    pass
else:
    collector.pause()
from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
session = open_session(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=0, episodes=2))
os._exit(0)
"""

ROWS = {
    "world": [sys.executable, "-c", _WORLD],
    "validate-task": [sys.executable, "-m", "robocfg", "validate", "robocfg/data/tasks/pick_place.yaml"],
    "validate-all": [sys.executable, "-m", "robocfg", "validate"],
}


def instructions(argv: list[str], cwd: Path, env: dict[str, str]) -> int:
    """Instructions (callgrind's ``Ir`` total) of one run of ``argv``."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "callgrind.out"
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", *argv], cwd=cwd,
                       env=env, capture_output=True, check=True)
        totals = re.search(r"^(?:summary|totals):\s+(\d+)", out.read_text(errors="replace"), re.M)
        if totals is None:
            raise RuntimeError(f"no totals in callgrind's output of {argv}")
        return int(totals.group(1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", action="append", type=Path, help="checkout to measure (repeatable)")
    ap.add_argument("--rows", default="world", help=f"comma-separated from {','.join(ROWS)}")
    ap.add_argument("--env", action="append", default=[], help="NAME=VALUE added to the children's environment")
    ap.add_argument("--runs", type=int, default=1, help="counted runs per row and checkout (after the warm-up)")
    args = ap.parse_args()
    roots = [r.resolve() for r in args.root or [ROOT]]
    extra = dict(item.split("=", 1) for item in args.env)
    pycache = os.environ.get("PYTHONPYCACHEPREFIX") or tempfile.mkdtemp(prefix="pycb-")
    print(f"python {sys.version.split()[0]}; extra environment {extra or '-'}")
    print(f"{'row':<15} {'checkout':<40} {'instructions (M)':>18}")
    for row in args.rows.split(","):
        for root in roots:
            env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
            env.update(PYTHONPATH=str(root), PYTHONHASHSEED="0", PYTHONPYCACHEPREFIX=pycache,
                       OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", **extra)
            env.setdefault("ROBOCFG_CACHE_DIR", tempfile.mkdtemp(prefix="robocfg-cache-"))
            subprocess.run(ROWS[row], cwd=root, env=env, capture_output=True, check=True)  # warm-up
            counts = [instructions(ROWS[row], root, env) for _ in range(args.runs)]
            print(f"{row:<15} {root!s:<40} {' '.join(f'{c / 1e6:.1f}' for c in counts):>18}", flush=True)


if __name__ == "__main__":
    main()
