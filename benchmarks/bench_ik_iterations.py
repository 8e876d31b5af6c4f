"""IK success versus an *iteration* budget: the `lm` backend's algorithmic success rate,
independent of machine load (a time budget on a shared machine measures the neighbours too).

Same targets as `robocfg bench ik` (TRAC-IK's protocol: N configurations uniform within the limits,
targets = FK of ee_link, seed = mid-limits, success = 1e-5 m, 1e-5 rad, within limits). Each query
may use at most K LM iterations in total (all restarts included); no time limit.

    python benchmarks/bench_ik_iterations.py [--robot panda] [-n 1000] [--budgets 25,50,100,200]
"""

from __future__ import annotations

import argparse

import numpy as np

from robocfg.checks import load_robot
from robocfg.config import catalog
from robocfg.kinematics.ik.bench import TOL_POS, TOL_ROT, make_targets
from robocfg.kinematics.ik.common import residuals
from robocfg.kinematics.model import KinematicModel


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--robot", default="panda")
    ap.add_argument("-n", "--targets", dest="n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--budgets", default="25,50,100,200")
    args = ap.parse_args()
    robot = load_robot(catalog.find("robots", args.robot))
    model = KinematicModel.from_robot(robot)
    _, targets = make_targets(model, args.n, args.seed, "ee")
    solver = model.solver("lm")
    print(f"IK on {robot.config.name}, n = {args.n}, seed {args.seed}: lm success vs total-iteration budget")
    print(f"{'iterations':>10}  {'success %':>9}  {'mean iterations':>15}  {'mean restarts':>13}")
    for k in (int(v) for v in args.budgets.split(",")):
        solver.max_total_iter = k
        rng = np.random.default_rng(args.seed)
        ok, its, rs = 0, [], []
        for T in targets:
            res = model.ik(T, model.mid, frame="ee", time_budget=1e9, rng=rng)
            pe, re = residuals(model.fk(res.q, "ee"), T)
            ok += pe <= TOL_POS and re <= TOL_ROT and model.within_limits(res.q)
            its.append(res.iterations)
            rs.append(res.restarts)
        print(f"{k:>10}  {100 * ok / args.n:>9.2f}  {np.mean(its):>15.1f}  {np.mean(rs):>13.2f}")
    solver.max_total_iter = None


if __name__ == "__main__":
    main()
