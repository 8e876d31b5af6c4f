"""Gymnasium env speed and the pick-place expert's success rate, side by side with panda-gym.

Both run in this one process on the same machine, in turn, at the same simulated time per env
step (0.04 s, panda-gym's default): env steps/s with uniformly random actions (episodes reset
when they end, as an RL loop would), mean reset time, and the scripted expert's success rate
through the env API (``env.unwrapped.expert_action()``) over ``--episodes`` seeded episodes.
panda-gym is optional (``pip install panda-gym`` into the benchmark's environment; it is not a
robocfg dependency); without it only robocfg's rows are printed.

    python benchmarks/bench_gym.py --steps 2000 --episodes 100 [--robot panda] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import asdict, dataclass

import gymnasium as gym
import numpy as np

import robocfg.envs  # noqa: F401  (registers robocfg/*-v0)


@dataclass
class Row:
    env: str
    steps_per_s: float  # env steps per wall-clock second, random actions, resets included
    reset_ms: float  # mean wall time of env.reset(), ms
    sim_time_per_step: float  # simulated seconds per env step
    expert_success: float | None = None  # fraction of episodes solved by the scripted expert
    expert_episodes: int = 0


def speed(env: gym.Env, steps: int, resets: int, seed: int = 0) -> tuple[float, float]:
    env.reset(seed=seed)
    env.action_space.seed(seed)
    t0 = time.perf_counter()
    for _ in range(steps):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    rate = steps / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    for k in range(resets):
        env.reset(seed=seed + 1 + k)
    return rate, (time.perf_counter() - t0) / resets * 1000


def expert(env: gym.Env, episodes: int) -> float:
    solved = 0
    for seed in range(episodes):
        env.reset(seed=seed)
        terminated = truncated = False
        info: dict = {}
        while not (terminated or truncated):
            _, _, terminated, truncated, info = env.step(env.unwrapped.expert_action())
        solved += bool(info["is_success"])
    return solved / episodes


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--resets", type=int, default=200)
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--robot", default="panda")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    rows: list[Row] = []
    try:
        import panda_gym  # noqa: F401  (registers Panda*-v3)

        for name in ("PandaReach-v3", "PandaPickAndPlace-v3"):
            env = gym.make(name)
            rate, reset_ms = speed(env, args.steps, args.resets)
            u = env.unwrapped
            rows.append(Row(f"panda-gym {name}", rate, reset_ms, u.sim.timestep * u.sim.n_substeps))
            env.close()
    except ImportError:
        print("panda-gym not installed: robocfg rows only")
    for name in ("Reach", "PickPlace"):
        env = gym.make(f"robocfg/{name}-v0", robot=args.robot, step_time=0.04)
        rate, reset_ms = speed(env, args.steps, args.resets)
        row = Row(f"robocfg/{name}-v0 ({args.robot})", rate, reset_ms, env.unwrapped.step_time)
        if name == "PickPlace" and args.episodes > 0:
            row.expert_success, row.expert_episodes = expert(env, args.episodes), args.episodes
        rows.append(row)
        env.close()
    print("| env | env steps/s | reset (ms) | simulated s/step | expert success |\n|---|---|---|---|---|")
    for r in rows:
        ok = "" if r.expert_success is None else f"{r.expert_success * 100:.1f} % of {r.expert_episodes}"
        print(f"| {r.env} | {r.steps_per_s:.0f} | {r.reset_ms:.2f} | {r.sim_time_per_step:.3f} | {ok} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump([asdict(r) for r in rows], f, indent=2)


if __name__ == "__main__":
    np.set_printoptions(precision=3)
    main()
