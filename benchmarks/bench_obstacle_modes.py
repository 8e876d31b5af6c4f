"""The pick-place obstacle task in its three free-space modes, side by side in one process:
``trajectory`` (IK + min-jerk, blind to the wall), ``planned`` (global planner) and ``reactive``
(follow-target controller), and ``trajectory`` on the same task with the wall taken out (the
same work with nothing in the way: the yardstick).

    python benchmarks/bench_obstacle_modes.py [--episodes 20] [--seed 0] [--rounds 2] [--modes ...] [--json out.json]

Per mode, in this order, all in one process:

1. a throw-away episode (one-off imports and caches out of the figures);
2. a *check* run of the episodes with a stand-in dataset sink that counts physics steps with a
   robot link or the cube inside the wall (PyBullet contact points, every step: it costs, so it is
   not timed);
3. ``--rounds`` rounds, the modes in turns (rotated order each round), each round:

   * an *interleaved* run (``_paired.interleaved_round``): one session per mode built (timed),
     then episode 0 of every mode, episode 1 of every mode, … and the sessions closed (timed):
     each mode's cost is a user's run of it (world build, set-up, episodes, report), and a load
     change on the machine hits the modes within one episode of each other. **The headline**:
     planned / trajectory without the wall, per round and the median over the rounds;
   * a *clean* whole run per mode (nothing added), each right after a *reference* reading (CPU µs
     a step of a world at rest: the machine's speed at that moment), and the garbage collector's
     CPU time and collections during it (``gc.callbacks``);
   * a *split* run per mode, where ``time.process_time`` is read around each part
     (``_cpu_split.Split``): PyBullet's ``stepSimulation`` by phase (steps, CPU µs a step), the
     planner's parts (goal IK, RRT-Connect, shortcutting, levelling, timing, the timed path's
     check, the direct-segment checks), the run's set-up (world build, the session's set-up — the
     planner's collision model, the reactive controller — and closing; once per run, divided by
     the episodes), robocfg's other own work.

   Every run must give the same records as the check run (same seed, same episodes): the
   benchmark says so.

Why interleaved (issue 18, round 6): timed one after the other, whole runs compare two states of
a shared machine, not two modes. On the 2-core laptop the planned mode's whole runs cost 165 or
245 ms an episode from one round to the next, and the trajectory mode's 150 or 207 (a bare
physics loop: 43–77 µs a step within a minute), while callgrind counts 1.105× the instructions
for planned / trajectory without the wall (``bench_obstacle_instructions.py``: a count the load
cannot move; code before bb78e86) and four passes of episodes alternating between the two modes
gave 1.12–1.13× CPU each while both modes' absolute CPU moved by 1.34× between passes.

CPU time (``time.process_time``) is the figure to trust on a loaded machine; the issue's goal is
in wall time: planned ≤ 1.3 × the trajectory mode without the wall (issue 18; with the wall in
place the trajectory mode runs into it and times out). Exit 0 when the goal is met by the
interleaved rounds' median wall-time ratio, every planned episode placed and no robot link inside
the wall. (Just over 300 lines: measuring, summary and printing of one table kept together.)
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from _cpu_split import PHYSICS, Split
from _paired import GcTimer, Reference, interleaved_round

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine.options import RunOptions
from robocfg.runners.pick_place import PickPlaceRunner, run_pick_place
from robocfg.sim.world import World

MODES = ("trajectory", "planned", "reactive", "trajectory_no_wall")
PHASES = ("setup", "pre_grasp", "approach", "grasp", "lift", "transport", "lower", "release", "retract")
PLANNING = ("goal IK", "RRT-Connect", "shortcut", "levelling", "timing", "timed-path check", "direct-segment checks")
ONCE = ("world build", "run set-up", "world close")  # once per run (not per episode), divided by the episodes
PARTS = [  # (module, class or None, function, part); exclusive time: an inner part is charged, not its caller
    ("pybullet", None, "stepSimulation", PHYSICS),
    ("robocfg.engine.session", "EpisodeSession", "_build_world", "world build"),
    ("robocfg.runners.pick_place", "PickPlaceSession", "prepare", "run set-up"),
    ("robocfg.engine.session", "EpisodeSession", "close", "world close"),
    ("robocfg.planning.drive", "PlannedDrive", "goal", "goal IK"),
    ("robocfg.planning.planner", "JointPlanner", "plan", "direct-segment checks"),
    ("robocfg.planning.planner", None, "rrt_connect", "RRT-Connect"),
    ("robocfg.planning.planner", None, "shortcut", "shortcut"),
    ("robocfg.planning.drive", "PlannedDrive", "levelled", "levelling"),
    ("robocfg.planning.planner", "JointPlanner", "timed", "timing"),
    ("robocfg.planning.planner", "JointPlanner", "trajectory_valid", "timed-path check"),
]


class WallContacts:
    """A dataset-sink stand-in: counts physics steps with a robot link or the cube inside the wall."""

    def __init__(self):
        self.robot_steps = self.cube_steps = self.steps = 0

    def begin(self, world, arm, obj, phase_of, phases=(), language=""):
        return _Episode(self, world, obj)

    def end(self, rec, index, seed, success, failed_phase, reason):
        pass


class _Episode:
    """The sink's tap (``robocfg.engine.dataset.EpisodeTap``): hooked into the world's physics
    steps from ``begin`` until ``stop``; it sends no commands, so nothing reaches the drives late."""

    lag_steps = 0

    def __init__(self, total: WallContacts, world, obj: int):
        self.total, self.world, self.obj = total, world, obj
        self.wall = world.bodies.get("wall")
        world.step_hooks.append(self.on_step)

    def stop(self) -> None:
        if self.on_step in self.world.step_hooks:
            self.world.step_hooks.remove(self.on_step)

    def on_step(self) -> None:
        if self.wall is None:
            return
        w, t = self.world, self.total
        robot = [k for k in w.contact_points(w.robot.body_id, self.wall) if k.distance < 0 and k.link_a != -1]
        cube = [k for k in w.contact_points(self.obj, self.wall) if k.distance < 0]
        t.robot_steps += bool(robot)
        t.cube_steps += bool(cube)
        t.steps += 1


class PhaseOf:
    """A sink that only hands the episode's phase to the split (no step hook: the world's loops
    stay as in a clean run)."""

    lag_steps = 0

    def __init__(self, split: Split):
        self.split = split

    def begin(self, world, arm, obj, phase_of, phases=(), language=""):
        self.split.phase_of = phase_of
        return self

    def stop(self) -> None:
        pass

    def end(self, rec, index, seed, success, failed_phase, reason):
        pass


def mode_task(task, mode: str):
    """``task`` in free-space ``mode``; ``…_no_wall``: with the wall taken out (the same pick-place
    work with nothing in the way: the yardstick the goal compares with)."""
    motion = mode.removesuffix("_no_wall")
    config = task.config.model_copy(update={"pick_place": task.config.pick_place.model_copy(update={"motion": motion})})
    if mode.endswith("_no_wall"):
        config = config.model_copy(update={"scene": config.scene.model_copy(update={"obstacles": []})})
    return replace(task, config=config)


def run_mode(task, episodes: int, seed: int, sink=None) -> tuple[list, float, float]:
    """(episode records, wall s, CPU s) of one run."""
    w0, c0 = time.perf_counter(), time.process_time()
    report, _ = run_pick_place(task, episodes=episodes, seed=seed, sink=sink)
    return report.episodes, time.perf_counter() - w0, time.process_time() - c0


def measure(task, modes: tuple[str, ...], episodes: int, seed: int, rounds: int) -> dict[str, dict]:
    tasks = {m: mode_task(task, m) for m in modes}
    out: dict[str, dict] = {}
    reference = Reference(World(mode_task(task, "trajectory_no_wall")))
    for m in modes:
        run_mode(tasks[m], 1, seed)  # throw-away
        contacts = WallContacts()
        records, _, _ = run_mode(tasks[m], episodes, seed, contacts)
        out[m] = {"records": records, "contacts": contacts, "wall": [], "cpu": [], "reference": [], "gc": [],
                  "inter_wall": [], "inter_cpu": [], "split": Split(PARTS), "same": True}
    runners = {m: (lambda m=m: PickPlaceRunner(tasks[m], RunOptions(seed=seed, episodes=episodes))) for m in modes}
    for r in range(rounds):
        order = list(modes[r % len(modes):] + modes[: r % len(modes)])
        for m, cost in interleaved_round(runners, order, episodes).items():
            x = out[m]
            x["inter_wall"].append(cost.wall / episodes)
            x["inter_cpu"].append(cost.cpu / episodes)
            x["same"] &= cost.records == x["records"]
        for m in order:
            x = out[m]
            x["reference"].append(reference())
            with GcTimer() as gct:
                records, wall, cpu = run_mode(tasks[m], episodes, seed)
            x["gc"].append((gct.seconds / episodes, gct.collections))
            x["wall"].append(wall / episodes)
            x["cpu"].append(cpu / episodes)
            split = x["split"]
            with split:
                split_records, _, _ = run_mode(tasks[m], episodes, seed, PhaseOf(split))
            x["same"] &= records == x["records"] and split_records == x["records"]
    reference.world.close()
    return out


def summary(m: str, x: dict, episodes: int, rounds: int) -> dict:
    eps, split, n = x["records"], x["split"], episodes * rounds
    physics, steps = split.physics()
    total = sum(split.cpu.values())
    own = {k: v / n * 1e3 for k, v in split.cpu.items() if not k.startswith(PHYSICS)}
    return {
        "mode": m, "success": sum(e.success for e in eps), "episodes": len(eps),
        "failures": sorted({f"{e.failed_phase}: {e.reason}" for e in eps if not e.success}),
        "same_records": bool(x["same"]), "sim_s_per_episode": float(np.mean([e.sim_time for e in eps])),
        "wall_s_per_episode": float(np.median(x["wall"])), "cpu_s_per_episode": float(np.median(x["cpu"])),
        "wall_rounds": x["wall"], "cpu_rounds": x["cpu"], "reference_us_per_step": x["reference"],
        "gc_ms_per_episode": [g[0] * 1e3 for g in x["gc"]], "gc_collections": [g[1] for g in x["gc"]],
        "interleaved_wall_rounds": x["inter_wall"], "interleaved_cpu_rounds": x["inter_cpu"],
        "split_cpu_ms_per_episode": total / n * 1e3, "physics_cpu_ms_per_episode": physics / n * 1e3,
        "steps_per_episode": steps / n, "physics_us_per_step": physics / max(steps, 1) * 1e6,
        "phases": {ph: {"steps": split.steps[ph] / n, "us_per_step": split.cpu[f"{PHYSICS}: {ph}"] / split.steps[ph] * 1e6}
                   for ph in PHASES if split.steps.get(ph)},
        "planning_ms": {k: own.get(k, 0.0) for k in PLANNING}, "once_ms": {k: own.get(k, 0.0) for k in ONCE},
        "other_own_ms": own.get("other", 0.0),
        "robot_wall_contact_steps": x["contacts"].robot_steps, "cube_wall_contact_steps": x["contacts"].cube_steps,
    }


def report(table: dict[str, dict], episodes: int, rounds: int) -> None:
    modes = list(table)
    print(f"pick_place_obstacle, {episodes} episodes × {rounds} rounds per mode; per episode: wall and CPU, median of the "
          f"interleaved runs (inter.) and of the clean whole runs; the split: mean of the split runs")
    print(f"{'mode':19s} {'success':>8s} {'sim s':>6s} {'inter. wall':>11s} {'inter. CPU':>10s} {'wall ms':>8s} {'CPU ms':>7s} "
          f"{'physics ms':>11s} {'steps':>6s} "
          f"{'µs/step':>8s} {'planning ms':>12s} {'set-up ms':>10s} {'other own ms':>13s} {'robot–wall':>11s} {'cube–wall':>10s}")
    for m in modes:
        x = table[m]
        print(f"{m:19s} {x['success']:>4d}/{x['episodes']:<3d} {x['sim_s_per_episode']:6.2f} "
              f"{np.median(x['interleaved_wall_rounds']) * 1e3:11.1f} {np.median(x['interleaved_cpu_rounds']) * 1e3:10.1f} "
              f"{x['wall_s_per_episode'] * 1e3:8.1f} "
              f"{x['cpu_s_per_episode'] * 1e3:7.1f} {x['physics_cpu_ms_per_episode']:11.1f} {x['steps_per_episode']:6.0f} "
              f"{x['physics_us_per_step']:8.1f} {sum(x['planning_ms'].values()):12.1f} {sum(x['once_ms'].values()):10.1f} "
              f"{x['other_own_ms']:13.1f} "
              f"{x['robot_wall_contact_steps']:11d} {x['cube_wall_contact_steps']:10d}"
              + ("" if x["same_records"] else "  (records differ between runs!)"))
    print("physics by phase: steps per episode, CPU µs a step")
    print(f"{'phase':10s} " + " ".join(f"{m:>24s}" for m in modes))
    for ph in PHASES:
        cells = [table[m]["phases"].get(ph) for m in modes]
        print(f"{ph:10s} " + " ".join(f"{c['steps']:>12.0f} {c['us_per_step']:>8.1f} µs" if c else f"{'–':>24s}" for c in cells))
    print("robocfg's own work, CPU ms per episode")
    for part in [*PLANNING, *ONCE, "other"]:
        vals = [table[m]["other_own_ms"] if part == "other" else {**table[m]["planning_ms"], **table[m]["once_ms"]}[part]
                for m in modes]
        print(f"{part:22s} " + " ".join(f"{v:>12.2f}" for v in vals))
    print("per round, ms an episode: interleaved run (wall / CPU), clean whole run (wall / CPU), the reference "
          "just before the clean run (CPU µs a step of a world at rest), the collector's CPU in the clean run")
    for r in range(rounds):
        for m in modes:
            x = table[m]
            print(f"{r:>3d} {m:19s} {x['interleaved_wall_rounds'][r] * 1e3:8.1f} / {x['interleaved_cpu_rounds'][r] * 1e3:6.1f}   "
                  f"{x['wall_rounds'][r] * 1e3:8.1f} / {x['cpu_rounds'][r] * 1e3:6.1f}   ref {x['reference_us_per_step'][r]:6.1f} µs   "
                  f"gc {x['gc_ms_per_episode'][r]:5.2f} ms {x['gc_collections'][r]}")


def round_ratios(table: dict[str, dict], mode: str, base: str = "trajectory_no_wall") -> dict[str, list[float]]:
    """``mode`` / ``base`` per round: interleaved and clean runs, wall and CPU, and the reference."""
    a, b = table[mode], table[base]
    keys = {"interleaved_wall": "interleaved_wall_rounds", "interleaved_cpu": "interleaved_cpu_rounds",
            "clean_wall": "wall_rounds", "clean_cpu": "cpu_rounds", "reference": "reference_us_per_step"}
    return {k: [x / y for x, y in zip(a[v], b[v], strict=True)] for k, v in keys.items()}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--modes", default=",".join(MODES), help="comma-separated subset (the ratio needs planned and trajectory_no_wall)")
    a = ap.parse_args()
    modes = tuple(m for m in MODES if m in a.modes.split(","))
    task = load_task(catalog.find("tasks", "pick_place_obstacle"))
    measured = measure(task, modes, a.episodes, a.seed, a.rounds)
    table = {m: summary(m, measured[m], a.episodes, a.rounds) for m in modes}
    report(table, a.episodes, a.rounds)
    if "planned" not in table or "trajectory_no_wall" not in table:
        return 0
    base, planned = table["trajectory_no_wall"], table["planned"]
    ratios = {m: round_ratios(table, m) for m in ("planned", "reactive", "trajectory") if m in table}
    for m, rr in ratios.items():
        print(f"{m} / trajectory without the wall, per round: interleaved wall {_fmt(rr['interleaved_wall'])}, "
              f"CPU {_fmt(rr['interleaved_cpu'])}; clean whole runs wall {_fmt(rr['clean_wall'])}, CPU {_fmt(rr['clean_cpu'])} "
              f"(reference before the clean runs {_fmt(rr['reference'])})")
    rr = ratios["planned"]
    ratio = {"interleaved_wall": float(np.median(rr["interleaved_wall"])), "interleaved_cpu": float(np.median(rr["interleaved_cpu"])),
             "interleaved_wall_max": max(rr["interleaved_wall"]), "clean_wall_medians": planned["wall_s_per_episode"] / base["wall_s_per_episode"],
             "clean_cpu_medians": planned["cpu_s_per_episode"] / base["cpu_s_per_episode"]}
    print(f"planned / trajectory without the wall: interleaved rounds' median wall {ratio['interleaved_wall']:.2f}× "
          f"(worst round {ratio['interleaved_wall_max']:.2f}×), CPU {ratio['interleaved_cpu']:.2f}×; "
          f"clean runs' medians wall {ratio['clean_wall_medians']:.2f}×, CPU {ratio['clean_cpu_medians']:.2f}×")
    if a.json:
        a.json.write_text(json.dumps({"table": table, "ratio": ratio, "round_ratios": ratios}, indent=1))
    ok = ratio["interleaved_wall"] <= 1.3 and planned["robot_wall_contact_steps"] == 0 and planned["success"] == planned["episodes"]
    print("goal (planned wall ≤ 1.3 × trajectory without the wall, interleaved rounds' median; every episode placed; "
          "0 robot–wall steps):", "met" if ok else "NOT met")
    return 0 if ok else 1


def _fmt(values: list[float]) -> str:
    return "[" + ", ".join(f"{v:.2f}×" for v in values) + "]"

if __name__ == "__main__":
    sys.exit(main())
