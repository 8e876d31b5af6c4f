"""Instructions per episode (callgrind): the obstacle task's planned mode vs the trajectory mode.

Instructions, not seconds: the planned mode against the trajectory mode without the wall, counted
by valgrind's callgrind (the same count on an idle or a loaded machine).

    python benchmarks/bench_obstacle_instructions.py [--episodes 5] [--seed 0] [--modes planned,trajectory_no_wall]

The script starts itself again under ``valgrind --tool=callgrind --instr-atstart=no`` (valgrind
must be installed; ≈ 50× slower than a plain run: 5 episodes a mode take ≈ 1–2 minutes on a laptop
core). In that child, per mode: a throw-away episode (imports, caches), then instrumentation on
(``callgrind_control -i on``), one run of ``--episodes`` episodes — world build, set-up, episodes,
report, as a user's run — and a dump named after the mode (``callgrind_control -d``). The parent
reads each dump's total and its largest shared objects and prints instructions per episode and
the ratio to the trajectory mode without the wall.

Why (issue 18, round 6): on a shared machine, CPU seconds of the same work swing by 1.3–1.5×
from one minute to the next, so two timed runs can disagree about which mode is slower. An
instruction count does not move with the load. It does not see cache misses or branch stalls:
physics-heavy code retires more instructions a nanosecond than the planner's, so the time ratio
is a little above the instruction ratio on a quiet machine.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections import Counter
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(modes: list[str], episodes: int, seed: int) -> None:
    """Runs inside callgrind: one instrumented run per mode, each dumped under the mode's name."""
    sys.path.insert(0, str(HERE))
    from bench_obstacle_modes import mode_task, run_mode

    from robocfg.checks import load_task
    from robocfg.config import catalog

    task = load_task(catalog.find("tasks", "pick_place_obstacle"))
    pid = str(os.getpid())
    for m in modes:
        t = mode_task(task, m)
        run_mode(t, 1, seed)  # throw-away: imports and first-use caches
        subprocess.run(["callgrind_control", "-i", "on", pid], check=True, capture_output=True)
        records, _, _ = run_mode(t, episodes, seed)
        subprocess.run(["callgrind_control", "-d", m, pid], check=True, capture_output=True)
        subprocess.run(["callgrind_control", "-i", "off", pid], check=True, capture_output=True)
        placed = sum(r.success for r in records)
        print(f"{m}: {placed}/{len(records)} placed, {sum(r.steps for r in records)} physics steps", flush=True)


def totals(path: Path) -> tuple[str, int, Counter]:
    """(dump name, total instructions, instructions by shared object) of one callgrind dump."""
    text = path.read_text(errors="replace")
    name = re.search(r"^desc: Trigger: .*?dump (\S+)", text, re.M)
    by_object: Counter = Counter()
    obj_names: dict[str, str] = {}
    current, after_call = "?", False
    for line in text.splitlines():
        m = re.match(r"^(c?)ob=\((\d+)\)(?: (.*))?$", line)
        if m:  # ob=: the object of the self costs that follow; a name is given the first time only
            if m.group(3):
                obj_names[m.group(2)] = Path(m.group(3)).name
            if not m.group(1):
                current = obj_names.get(m.group(2), "?")
            continue
        if line.startswith("calls="):
            after_call = True  # the next cost line is the call's inclusive cost: not self cost
            continue
        m = re.match(r"^(?:[+-]?\d+|\*) (\d+)$", line)
        if m:
            if not after_call:
                by_object[current] += int(m.group(1))
            after_call = False
    # the total is the sum of the self costs (the second dump's own "totals:" line read
    # 2⁶⁴ − 2.9·10⁸ here: not used)
    return (name.group(1) if name else path.name), sum(by_object.values()), by_object


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--modes", default="planned,trajectory_no_wall")
    ap.add_argument("--keep", type=Path, help="keep the callgrind dumps in this folder (for callgrind_annotate)")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    modes = a.modes.split(",")
    if a.child:
        child(modes, a.episodes, a.seed)
        return 0
    if shutil.which("valgrind") is None or shutil.which("callgrind_control") is None:
        print("valgrind (callgrind) is not installed here: nothing counted")
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        cmd = ["valgrind", "--tool=callgrind", "--instr-atstart=no", f"--callgrind-out-file={out}",
               sys.executable, __file__, "--child", "--episodes", str(a.episodes), "--seed", str(a.seed), "--modes", a.modes]
        p = subprocess.run(cmd, capture_output=True, text=True)
        print("\n".join(line for line in p.stdout.splitlines() if line.strip()))
        if p.returncode != 0:
            print(p.stderr[-3000:])
            return 1
        files = sorted(Path(tmp).glob("cg.out*"))
        dumps = {name: (total, objs) for name, total, objs in map(totals, files)}
        if a.keep is not None:
            a.keep.mkdir(parents=True, exist_ok=True)
            for f in files:
                shutil.copy(f, a.keep / f.name)
    print(f"instructions per episode (callgrind), {a.episodes} episodes a mode, world build and set-up included:")
    for m in modes:
        total, objs = dumps.get(m, (0, Counter()))
        top = ", ".join(f"{k} {v / a.episodes / 1e6:.0f}M" for k, v in objs.most_common(6))
        print(f"  {m:19s} {total / a.episodes / 1e6:8.1f} M   ({top})")
    if "planned" in dumps and "trajectory_no_wall" in dumps and dumps["trajectory_no_wall"][0]:
        print(f"planned / trajectory without the wall: {dumps['planned'][0] / dumps['trajectory_no_wall'][0]:.3f}× the instructions")
    return 0


if __name__ == "__main__":
    sys.exit(main())
