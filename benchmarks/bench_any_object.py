"""Robot × object matrix: the default pick-place task, unchanged but for its object, on every
built-in robot and a range of objects (primitives of every shape, 3–9 cm, 0.05–0.5 kg, and mesh
objects from pybullet_data).

    python benchmarks/bench_any_object.py --episodes 20 [--robots panda,xarm6] [--objects cube_5cm,duck]
                                          [--task pick_place] [--workers 2] [--json out.json] [--markdown table.md]

``--task pick_place_reach`` runs the same matrix on the task whose spots are fractions of each
arm's reach (``placement: reach``), where the industrial arms are not rejected as out of reach.

Before simulating, each cell is checked the way ``validate`` and ``run`` check it: the task must
load (an object wider than the open gripper is an error), a mesh wider than the gripper as a whole
is rejected too (its warning), and the object and place spots must be in the arm's reach (IK).
Rejected cells print the reason and are left out of the success rate; the others run
``--episodes`` randomised episodes (the task's own randomisation, seed ``--seed``) and report
successes and failures by phase. Cells run in ``--workers`` processes; results do not depend on
the number of workers.
"""

from __future__ import annotations

import argparse
import json
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path

PD = "pybullet_data://"
OBJECTS: dict[str, dict] = {
    "cube_5cm": {"shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.1},
    "cube_3cm": {"shape": "box", "size": [0.03, 0.03, 0.03], "mass": 0.05},
    "box_4x6x8": {"shape": "box", "size": [0.04, 0.06, 0.08], "mass": 0.2},
    "bar_9x3x4": {"shape": "box", "size": [0.09, 0.03, 0.04], "mass": 0.15},
    "heavy_5x5x6": {"shape": "box", "size": [0.05, 0.05, 0.06], "mass": 0.5},
    "cylinder_standing": {"shape": "cylinder", "size": [0.025, 0.09], "mass": 0.15},
    "cylinder_lying": {"shape": "cylinder", "size": [0.02, 0.08], "mass": 0.1, "euler_deg": [90.0, 0.0, 0.0]},
    "sphere_6cm": {"shape": "sphere", "size": [0.03], "mass": 0.1},
    "capsule_lying": {"shape": "capsule", "size": [0.02, 0.04], "mass": 0.1, "euler_deg": [90.0, 0.0, 0.0]},
    "duck": {"shape": "mesh", "size": [0.8, 0.8, 0.8], "mesh": PD + "duck_vhacd.urdf"},
    "random_009": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/009/009.urdf"},
    "random_014": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/014/014.urdf"},
    "random_023": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/023/023.urdf"},
    "random_033": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/033/033.urdf"},
    "random_003": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/003/003.urdf"},
    "random_000": {"shape": "mesh", "size": [1.0, 1.0, 1.0], "mesh": PD + "random_urdfs/000/000.urdf"},
}


@dataclass
class Cell:
    """One robot × object result: ``rejected`` (the reason, checked before simulating) or the
    episodes run, successes and failures by phase."""

    robot: str
    object: str
    rejected: str | None = None
    episodes: int = 0
    successes: int = 0
    failures_by_phase: dict[str, int] = field(default_factory=dict)
    failure_reasons: dict[str, int] = field(default_factory=dict)
    wall_s: float = 0.0


def task_file(folder: Path, robot: str, name: str, task: str = "pick_place") -> Path:
    """The pick-place task ``task`` (default: the default one) with its object replaced (nothing
    else). The robot is given as ``--robot`` gives it (``load_task(robot_override=...)``), so the
    file still names the robot its spots were written for and ``placement: auto`` maps them."""
    import yaml

    from robocfg.config import catalog

    data = yaml.safe_load(catalog.find("tasks", task).read_text())
    old = data["pick_place"]["object"]
    data["pick_place"]["object"] = {"name": name, "position": old["position"], "euler_deg": [0.0, 0.0, 0.0],
                                    "color": old["color"], **OBJECTS[name]}
    path = folder / f"{robot}__{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def run_cell(args: tuple[str, str, int, int, str, str]) -> Cell:
    robot, name, episodes, seed, folder, task_name = args
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.errors import ConfigError
    from robocfg.motion.placement import resolve_placement
    from robocfg.runners.pick_place import run_pick_place

    cell = Cell(robot, name)
    t0 = time.perf_counter()
    try:
        task = load_task(task_file(Path(folder), robot, name, task_name), robot_override=robot)
    except ConfigError as exc:
        cell.rejected = "; ".join(f"{p.path}: {p.message}" for p in exc.problems if p.severity == "error")
        return cell
    too_wide = [w for w in task.warnings if "narrowest horizontal side" in w.message]
    unreachable = [r for r in resolve_placement(task).reach if r.nominal]  # as ``run`` checks it
    if too_wide or unreachable:
        cell.rejected = too_wide[0].message if too_wide else f"{unreachable[0].phase}: {unreachable[0].reason}"
        return cell
    report, _ = run_pick_place(task, episodes=episodes, seed=seed)
    cell.episodes, cell.successes = report.summary.episodes, report.summary.successes
    cell.failures_by_phase = dict(report.summary.failures_by_phase)
    cell.failure_reasons = dict(Counter(f"{e.failed_phase}: {_short(e.reason)}" for e in report.episodes if not e.success))
    cell.wall_s = time.perf_counter() - t0
    return cell


def _short(reason: str) -> str:
    """A failure reason without its numbers, so that alike failures count together."""
    import re

    return re.sub(r"-?\d+(\.\d+)?", "#", reason)


def markdown(cells: list[Cell], robots: list[str], objects: list[str], episodes: int, seed: int) -> str:
    """The success table (robots × objects), the overall rate over feasible cells, failures by
    phase, and the rejected cells with their reasons."""
    by = {(c.robot, c.object): c for c in cells}
    lines = ["| robot | " + " | ".join(objects) + " |", "|---|" + "---|" * len(objects)]
    for r in robots:
        row = []
        for o in objects:
            c = by[(r, o)]
            row.append("rejected" if c.rejected else f"{c.successes}/{c.episodes}")
        lines.append(f"| {r} | " + " | ".join(row) + " |")
    feasible = [c for c in cells if not c.rejected]
    runs, ok = sum(c.episodes for c in feasible), sum(c.successes for c in feasible)
    phases: Counter = Counter()
    for c in feasible:
        phases.update(c.failures_by_phase)
    lines += ["", f"Feasible cells: {len(feasible)} of {len(cells)}; success over them: {ok}/{runs} "
                  f"({ok / max(runs, 1):.1%}); {episodes} episodes per cell, seed {seed}.",
              "Failures by phase: " + (", ".join(f"{k} {v}" for k, v in phases.most_common()) or "none") + ".", "",
              "Rejected before simulating:", ""]
    lines += [f"- {c.robot} × {c.object}: {c.rejected}" for c in cells if c.rejected]
    return "\n".join(lines) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--robots", default=None, help="comma-separated robot names (default: every built-in)")
    ap.add_argument("--objects", default=None, help=f"comma-separated, from: {', '.join(OBJECTS)}")
    ap.add_argument("--task", default="pick_place", help="a pick_place task whose object is replaced")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", default=None)
    ap.add_argument("--markdown", default=None)
    args = ap.parse_args()

    import tempfile

    from robocfg.config import catalog

    robots = args.robots.split(",") if args.robots else sorted(catalog.available("robots"))
    objects = args.objects.split(",") if args.objects else list(OBJECTS)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        jobs = [(r, o, args.episodes, args.seed, folder, args.task) for r in robots for o in objects]
        with ProcessPoolExecutor(max_workers=args.workers) as pool:
            cells = []
            for cell in pool.map(run_cell, jobs):
                cells.append(cell)
                status = f"rejected: {cell.rejected}" if cell.rejected else f"{cell.successes}/{cell.episodes}"
                print(f"{cell.robot:>20} × {cell.object:<18} {status}  {cell.failure_reasons or ''}", flush=True)
    table = markdown(cells, robots, objects, args.episodes, args.seed)
    print()
    print(table)
    print(f"wall time {time.perf_counter() - t0:.0f} s with {args.workers} workers")
    if args.markdown:
        Path(args.markdown).write_text(table)
    if args.json:
        Path(args.json).write_text(json.dumps([asdict(c) for c in cells], indent=1))


if __name__ == "__main__":
    main()
