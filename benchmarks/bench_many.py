"""Several-object tasks (issue 18) on several robots: bin-to-bin with five objects, shelf placing,
clear-table and clear-table with mesh objects (a duck and a random_urdfs bar among a box and a
cylinder, into the bin), ``run pick-place-many`` episodes per (task, robot).

    python benchmarks/bench_many.py [--episodes 50] [--seed 0] [--robots panda,ur5e_robotiq_2f85]
                                    [--tasks pick_place_many,pick_place_shelf,clear_table,clear_table_mesh]
                                    [--workers 1] [--json out.json]

Per (task, robot): episodes with every object placed, objects placed, robot–fixture contacts
(polls every 4 physics steps at which a robot link touched a fixture part or an obstacle: a
point PyBullet reports at distance ≤ 0; the goal is 0) and, under the table, which link touched
which part in which phase; the closest robot–fixture distance PyBullet reported (it also reports
pairs a few mm apart, which are not contacts); failures by phase and by object, simulated and
wall time per episode. With
``--workers N`` the episodes of each (task, robot) are spread over N processes (the same records
as one process: episode k depends only on the seed and k). Goal (issue 18): ≥ 95 % success and
0 robot–fixture contacts over 50 episodes per task and robot.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TASKS = ("pick_place_many", "pick_place_shelf", "clear_table", "clear_table_mesh")
ROBOTS = ("panda", "ur5e_robotiq_2f85")


def run(task_name: str, robot: str, episodes: int, seed: int, workers: int) -> dict:
    """One (task, robot): ``robocfg run pick-place-many`` in a fresh process (wall time includes
    its start, ≈ 1–2 s), the figures read from its --json report."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "report.json"
        cmd = [sys.executable, "-m", "robocfg", "run", "pick-place-many", task_name, "--robot", robot,
               "-n", str(episodes), "--seed", str(seed), "--json", str(out), "-q", "--min-success", "0"]
        if workers > 1:
            cmd += ["--workers", str(workers)]
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
        wall = time.perf_counter() - t0
        if not out.exists():
            raise SystemExit(f"{' '.join(cmd)} wrote no report:\n{proc.stdout}{proc.stderr}")
        report = json.loads(out.read_text())
    s = report["summary"]
    failures: dict[str, int] = {}
    for e in report["episodes"]:
        if not e["success"]:
            key = f"{e['failed_phase']}: {e['reason']}"
            failures[key] = failures.get(key, 0) + 1
    return {"task": task_name, "robot": robot, "episodes": s["episodes"], "successes": s["successes"],
            "objects_placed": s["objects_placed"], "objects_total": s["objects_total"],
            "robot_fixture_contacts": s["robot_fixture_contacts"], "failures_by_phase": s["failures_by_phase"],
            "failures_by_object": s["failures_by_object"], "contacts_by_kind": s.get("contacts_by_kind", {}),
            "closest_fixture_mm": None if s.get("closest_fixture") is None else 1000 * s["closest_fixture"],
            "sim_s_per_episode": s["mean_sim_time"],
            "wall_s_per_episode": wall / episodes,
            "failures": [f"{n} × {k}" for k, n in sorted(failures.items(), key=lambda t: -t[1])]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=50)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robots", default=",".join(ROBOTS))
    ap.add_argument("--tasks", default=",".join(TASKS))
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    rows = [run(t, r, a.episodes, a.seed, a.workers) for t in a.tasks.split(",") for r in a.robots.split(",")]
    print(f"{'task':22s} {'robot':18s} {'success':>9s} {'objects':>9s} {'contacts':>8s} {'sim s/ep':>8s} "
          f"{'wall s/ep':>9s} {'closest mm':>10s}  failures by phase")
    for x in rows:
        phases = ", ".join(f"{k}: {v}" for k, v in x["failures_by_phase"].items()) or "none"
        closest = "-" if x["closest_fixture_mm"] is None else f"{x['closest_fixture_mm']:.1f}"
        print(f"{x['task']:22s} {x['robot']:18s} {x['successes']:>4d}/{x['episodes']:<4d} "
              f"{x['objects_placed']:>4d}/{x['objects_total']:<4d} {x['robot_fixture_contacts']:8d} "
              f"{x['sim_s_per_episode']:8.2f} {x['wall_s_per_episode']:9.2f} {closest:>10s}  {phases}")
        for line in x["failures"]:
            print(f"    {line}")
        for kind, n in sorted(x["contacts_by_kind"].items(), key=lambda t: -t[1]):
            print(f"    contact polls {n} × {kind}")
    if a.json:
        a.json.write_text(json.dumps(rows, indent=1))
    ok = all(x["successes"] >= 0.95 * x["episodes"] and x["robot_fixture_contacts"] == 0 for x in rows)
    print("goal (≥ 95 % success and 0 robot-fixture contacts per task and robot):", "met" if ok else "NOT met")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
