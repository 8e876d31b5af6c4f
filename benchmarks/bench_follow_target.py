"""Follow-target benchmark (Panda): static target, circle tracking, obstacle on the straight-line path.

    python benchmarks/bench_follow_target.py [--trials 20] [--seed 0] [--json out.json] [--only static,circle,obstacle]

Figures (issue 6): static target ≤ 1 mm / 0.01 rad at convergence; circle r = 0.1 m, period 4 s:
RMS ≤ 5 mm after the first second; obstacle on the straight-line path from the start TCP to the
target: zero robot–obstacle contacts and minimum clearance ≥ margin − 5 mm over ``--trials``
seeded random placements; median control step ≤ 2 ms. Prints one table per scenario.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.config.commands import FollowObstacle, FollowTargetParams, Motion
from robocfg.runners.follow_target import run_follow_target

HOME_TCP = np.array([0.307, 0.0, 0.487])  # Panda home TCP (m), the straight path's start


def _params(base: FollowTargetParams, **update) -> FollowTargetParams:
    return FollowTargetParams.model_validate({**base.model_dump(), **update})


def static_case(task, base: FollowTargetParams) -> dict:
    targets = [[0.5, 0.2, 0.4], [0.45, -0.25, 0.3], [0.6, 0.0, 0.25], [0.35, 0.3, 0.5]]
    rows = []
    for c in targets:
        p = _params(base, motion=Motion(type="static", center=c).model_dump(), duration=3.0, with_obstacle=False)
        r = run_follow_target(task, params=p)
        rows.append({"target": c, "pos_mm": r.final_position_error_mm, "rot_rad": math.radians(r.final_orientation_error_deg),
                     "step_ms": r.step_time_median_ms, "step_cpu_ms": r.step_cpu_median_ms, "ok": r.final_position_error_mm <= 1.0
                     and math.radians(r.final_orientation_error_deg) <= 0.01})
    return {"rows": rows, "pass": all(x["ok"] for x in rows)}


def circle_case(task, base: FollowTargetParams) -> dict:
    p = _params(base, motion=Motion(type="circle", center=[0.5, 0.0, 0.4], radius=0.1, period=4.0, plane="yz").model_dump(),
                duration=8.0, settle_time=1.0, with_obstacle=False)
    r = run_follow_target(task, params=p)
    e = r.position_error_mm
    return {"rms_mm": e.rms, "mean_mm": e.mean, "max_mm": e.max, "rot_rms_deg": r.orientation_error_deg.rms,
            "step_median_ms": r.step_time_median_ms, "step_p95_ms": r.step_time_p95_ms,
            "step_cpu_median_ms": r.step_cpu_median_ms, "step_cpu_p95_ms": r.step_cpu_p95_ms, "pass": e.rms <= 5.0}


def obstacle_placements(n: int, seed: int) -> list[tuple[list[float], FollowObstacle]]:
    """Seeded (target, obstacle) pairs: the obstacle sits on the segment start TCP → target."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        side = rng.choice([-1.0, 1.0])
        target = np.array([rng.uniform(0.45, 0.6), side * rng.uniform(0.15, 0.35), rng.uniform(0.2, 0.4)])
        u = rng.uniform(0.4, 0.6)
        centre = HOME_TCP + u * (target - HOME_TCP)
        shape = rng.choice(["sphere", "box", "capsule"])
        if shape == "sphere":
            size = [float(rng.uniform(0.03, 0.05))]
            extent = size[0]
        elif shape == "box":
            e = float(rng.uniform(0.05, 0.08))
            size, extent = [e, e, e], e * math.sqrt(3) / 2
        else:
            size = [float(rng.uniform(0.02, 0.03)), float(rng.uniform(0.05, 0.1))]
            extent = size[0] + size[1] / 2
        if np.linalg.norm(target - centre) - extent < 0.1 or np.linalg.norm(HOME_TCP - centre) - extent < 0.1:
            continue  # the hand needs room at both ends
        yaw = float(rng.uniform(-180, 180))
        ob = FollowObstacle(name="obstacle", shape=shape, size=size, position=[float(v) for v in centre],
                            euler_deg=[90.0 if shape == "capsule" else 0.0, 0.0, yaw])
        out.append(([float(v) for v in target], ob))
    return out


def obstacle_case(task, base: FollowTargetParams, trials: int, seed: int) -> dict:
    rows = []
    for k, (target, ob) in enumerate(obstacle_placements(trials, seed)):
        p = _params(base, motion=Motion(type="static", center=target).model_dump(), duration=5.0,
                    with_obstacle=True, obstacles=[ob.model_dump()])
        r = run_follow_target(task, params=p)
        rows.append({"trial": k, "shape": ob.shape, "target": target, "contacts": r.contacts,
                     "min_clearance_mm": r.min_clearance_mm, "final_mm": r.final_position_error_mm,
                     "reached": r.reached, "escapes": r.escapes, "soft": r.soft_steps, "fallback": r.fallback_steps,
                     "step_median_ms": r.step_time_median_ms, "step_p95_ms": r.step_time_p95_ms,
                     "step_cpu_median_ms": r.step_cpu_median_ms, "step_cpu_p95_ms": r.step_cpu_p95_ms})
    margin_mm = base.safety_margin * 1000
    ok = all(x["contacts"] == 0 and x["min_clearance_mm"] >= margin_mm - 5.0 for x in rows)
    return {"rows": rows, "pass": ok, "reached": sum(x["reached"] for x in rows),
            "worst_clearance_mm": min(x["min_clearance_mm"] for x in rows),
            "step_median_ms": float(np.median([x["step_median_ms"] for x in rows])),
            "step_cpu_median_ms": float(np.median([x["step_cpu_median_ms"] for x in rows])),
            "step_cpu_p95_ms": float(np.median([x["step_cpu_p95_ms"] for x in rows]))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=20)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--only", default="static,circle,obstacle")
    ap.add_argument("--json", type=Path)
    a = ap.parse_args(argv)
    task = load_task(catalog.find("tasks", "follow_target"))
    base = task.config.follow_target
    out: dict = {}
    which = a.only.split(",")
    if "static" in which:
        out["static"] = s = static_case(task, base)
        print("static target (3 s)            pos mm    rot rad    step ms (wall / CPU)")
        for x in s["rows"]:
            print(f"  {x['target']!s:28s} {x['pos_mm']:8.4f}  {x['rot_rad']:.2e}  {x['step_ms']:7.3f} / {x['step_cpu_ms']:.3f}")
        print(f"  pass (≤ 1 mm / 0.01 rad): {s['pass']}")
    if "circle" in which:
        out["circle"] = c = circle_case(task, base)
        print(f"circle r 0.1 m, 4 s: RMS {c['rms_mm']:.2f} mm, mean {c['mean_mm']:.2f}, max {c['max_mm']:.2f} "
              f"(after 1 s), rot RMS {c['rot_rms_deg']:.3f} deg; step median {c['step_median_ms']:.3f} ms, "
              f"p95 {c['step_p95_ms']:.3f} ms (CPU {c['step_cpu_median_ms']:.3f} / {c['step_cpu_p95_ms']:.3f}); "
              f"pass (RMS ≤ 5 mm): {c['pass']}")
    if "obstacle" in which:
        out["obstacle"] = o = obstacle_case(task, base, a.trials, a.seed)
        print("obstacle on the path  shape    contacts  min clear mm  final mm  reached  escapes  soft  fallback  step ms (wall / CPU)")
        for x in o["rows"]:
            print(f"  {x['trial']:3d}                {x['shape']:8s} {x['contacts']:6d}  {x['min_clearance_mm']:11.2f}  "
                  f"{x['final_mm']:8.2f}  {x['reached']!s:7s}  {x['escapes']:6d}  {x['soft']:4d}  {x['fallback']:8d}  "
                  f"{x['step_median_ms']:6.3f} / {x['step_cpu_median_ms']:.3f}")
        print(f"  pass (0 contacts, clearance ≥ margin − 5 mm in all {a.trials}): {o['pass']}; "
              f"reached {o['reached']}/{a.trials}; worst clearance {o['worst_clearance_mm']:.2f} mm; "
              f"median step {o['step_median_ms']:.3f} ms (CPU {o['step_cpu_median_ms']:.3f}, CPU p95 {o['step_cpu_p95_ms']:.3f})")
    if a.json:
        a.json.write_text(json.dumps(out, indent=2, default=float) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
