"""Gymnasium environments for any robot YAML. Importing this module registers them::

    import gymnasium as gym
    import robocfg.envs  # noqa: F401
    env = gym.make("robocfg/PickPlace-v0", robot="ur5e_robotiq_2f85")

``robocfg/Reach-v0``, ``robocfg/Push-v0``, ``robocfg/PickPlace-v0``, ``robocfg/FollowTarget-v0``;
constructor options are those of ``robocfg.envs.core.RobotEnv`` (``robot``, ``control``,
``reward_type``, ``render_mode``, ``step_time``...).
"""

from __future__ import annotations

import gymnasium as gym

from robocfg.envs.core import RobotEnv
from robocfg.envs.tasks import FollowTargetEnv, PickPlaceEnv, PushEnv, ReachEnv

ENVS = {"Reach": (ReachEnv, 50), "Push": (PushEnv, 100), "PickPlace": (PickPlaceEnv, 100),
        "FollowTarget": (FollowTargetEnv, 200)}
"""name → (class, max_episode_steps)."""

for _name, (_cls, _steps) in ENVS.items():
    if f"robocfg/{_name}-v0" not in gym.registry:
        gym.register(f"robocfg/{_name}-v0", entry_point=f"{_cls.__module__}:{_cls.__name__}",
                     max_episode_steps=_steps)

__all__ = ["ENVS", "FollowTargetEnv", "PickPlaceEnv", "PushEnv", "ReachEnv", "RobotEnv"]
