"""Gymnasium environments: API conformance for every env x built-in robot, seeded resets, HER
rewards, the expert through the env API, rendering, joint control and vectorisation."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import robocfg.envs
from robocfg.config import catalog

ROBOTS = sorted(catalog.available("robots"))


@pytest.mark.parametrize("robot", ROBOTS)
def test_check_env_every_env(robot):
    for name in robocfg.envs.ENVS:
        env = gym.make(f"robocfg/{name}-v0", robot=robot)
        try:
            check_env(env.unwrapped, skip_render_check=True)
        finally:
            env.close()


def _rollout(env, seed, n=8):
    obs, _ = env.reset(seed=seed)
    out = [obs["observation"].copy(), obs["desired_goal"].copy()]
    rng = np.random.default_rng(seed)
    for _ in range(n):
        obs, *_ = env.step(rng.uniform(-1, 1, env.action_space.shape))
        out.append(obs["observation"].copy())
    return np.concatenate(out)


def test_same_seed_same_episode_and_other_seed_differs():
    env = gym.make("robocfg/PickPlace-v0", robot="panda")
    a, b, c = _rollout(env, 5), _rollout(env, 5), _rollout(env, 6)
    env.close()
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_compute_reward_batched_for_her():
    env = gym.make("robocfg/Reach-v0", robot="panda").unwrapped
    achieved = np.array([[0.3, 0.0, 0.2], [0.3, 0.0, 0.2]])
    desired = np.array([[0.3, 0.0, 0.22], [0.5, 0.0, 0.2]])
    np.testing.assert_array_equal(env.compute_reward(achieved, desired, {}), [0.0, -1.0])
    env.reward_type = "dense"
    np.testing.assert_allclose(env.compute_reward(achieved, desired, {}), [-0.02, -0.2], atol=1e-6)
    env.close()


def test_reach_moves_the_tcp_towards_the_goal_with_ee_deltas():
    env = gym.make("robocfg/Reach-v0", robot="ur5e_robotiq_2f85")
    obs, info = env.reset(seed=1)
    d0 = info["distance"]
    for _ in range(40):
        a = np.clip((obs["desired_goal"] - obs["achieved_goal"]) / 0.05, -1, 1)
        obs, reward, terminated, _, info = env.step(a)
        if terminated:
            break
    env.close()
    assert d0 > 0.05 and info["is_success"] and reward == 0.0


@pytest.mark.parametrize("robot", ["panda", "kuka_iiwa_suction"])
def test_expert_places_the_cube(robot):
    env = gym.make("robocfg/PickPlace-v0", robot=robot)
    for seed in range(3):
        obs, info = env.reset(seed=seed)
        start = obs["achieved_goal"].copy()
        terminated = truncated = False
        while not (terminated or truncated):
            obs, _, terminated, truncated, info = env.step(env.unwrapped.expert_action())
        assert info["is_success"], (robot, seed, info)
        assert np.linalg.norm(obs["achieved_goal"] - start) > 0.05  # the cube really moved
    env.close()


def test_an_arm_that_cannot_reach_the_floor_works_on_the_stand_run_adds():
    """dual_arm_lift (arms 0.76 m up): the env resolves the pick_place task's placement as
    ``run pick-place`` does, so the same stand is in its world and its workspace lies on the
    stand's top; the expert places the cube there (on the floor the arm reached nothing)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.motion.placement import resolve_placement

    stand = resolve_placement(load_task(catalog.find("tasks", "pick_place"), robot_override="dual_arm_lift")).stand
    assert stand is not None
    env = gym.make("robocfg/PickPlace-v0", robot="dual_arm_lift")
    ws = env.unwrapped.workspace
    assert "placement_stand/block" in env.unwrapped.world.bodies
    assert ws.floor == pytest.approx(stand.position[2] + stand.size[2])
    obs, info = env.reset(seed=0)
    assert obs["achieved_goal"][2] == pytest.approx(ws.floor + 0.025, abs=2e-3)  # the cube rests on the stand
    terminated = truncated = False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(env.unwrapped.expert_action())
    assert info["is_success"], info
    env.close()


def test_joint_control_moves_the_commanded_joint():
    env = gym.make("robocfg/Reach-v0", robot="panda", control="joints")
    env.reset(seed=0)
    arm = env.unwrapped.arm
    q0 = arm.joint_positions()
    a = np.zeros(env.action_space.shape)
    a[0] = 1.0
    for _ in range(5):
        env.step(a)
    dq = arm.joint_positions() - q0
    env.close()
    assert env.action_space.shape == (7,)
    assert dq[0] > 0.1 and np.all(np.abs(dq[1:]) < 0.05)


def test_render_rgb_array():
    env = gym.make("robocfg/Push-v0", robot="panda", render_mode="rgb_array", render_size=(64, 48))
    env.reset(seed=0)
    frame = env.render()
    env.close()
    assert frame.shape == (48, 64, 3) and frame.dtype == np.uint8 and frame.std() > 1.0


def test_follow_target_goal_moves_and_never_terminates():
    env = gym.make("robocfg/FollowTarget-v0", robot="panda")
    obs, _ = env.reset(seed=0)
    g0 = obs["desired_goal"].copy()
    for _ in range(10):
        obs, _, terminated, _, _ = env.step(np.zeros(3))
        assert not terminated
    env.close()
    assert 0.01 < np.linalg.norm(obs["desired_goal"] - g0) < 0.2


def test_async_vector_env_with_two_workers():
    envs = gym.vector.AsyncVectorEnv([lambda: gym.make("robocfg/Reach-v0", robot="panda")] * 2)
    try:
        obs, _ = envs.reset(seed=[0, 1])
        assert obs["observation"].shape == (2, 6)
        assert not np.allclose(obs["desired_goal"][0], obs["desired_goal"][1])
        obs, reward, *_ = envs.step(envs.action_space.sample())
        assert reward.shape == (2,)
    finally:
        envs.close()


def test_step_time_is_exact_whole_physics_steps():
    env = gym.make("robocfg/Reach-v0", robot="panda", step_time=0.04).unwrapped
    env.reset(seed=0)
    env.step(np.zeros(3))
    assert env.world.dt * env.substeps == pytest.approx(0.04)
    assert env.world.t == pytest.approx(0.04)  # one env step = 0.04 s simulated
    env.close()
