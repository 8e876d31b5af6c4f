"""Re-simulate a stored pick-place episode from its recorded actions alone and compare outcomes.

The episode's world is rebuilt from the task and seed stored in the dataset (object pose, mass,
friction: episode k of seed s), then the recorded actions drive the robot through the same
command gate as when recording, for the same number of physics steps. The outcome matches when
success is the same and the object ends within ``tolerance`` (m) of its recorded final position.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from robocfg.datasets.episode import DatasetLayout
from robocfg.datasets.read import read_episode, read_info
from robocfg.errors import RobocfgError

MATCH_TOLERANCE = 0.001  # m


@dataclass(frozen=True)
class ReplayResult:
    """Recorded vs replayed: success, object final position (world, m), their distance (m)."""

    episode: int
    recorded_success: bool
    replayed_success: bool
    replayed_reason: str
    recorded_object: list[float]
    replayed_object: list[float]
    distance: float
    tolerance: float

    @property
    def matches(self) -> bool:
        return self.recorded_success == self.replayed_success and self.distance <= self.tolerance


def replay_episode(root: Path, k: int, tolerance: float = MATCH_TOLERANCE) -> ReplayResult:
    from robocfg.checks import load_task
    from robocfg.motion.moves import MoveFailed
    from robocfg.runners.pick_place import _StateMachine, _Tools, episode_setups
    from robocfg.sim.world import World

    info, ep = read_info(root), read_episode(root, k)
    run = info.run
    task_path = Path(run.get("task_path", ""))
    if not task_path.is_file():
        raise RobocfgError(f"replay needs the task file the dataset was recorded from: {task_path} is missing")
    task = load_task(task_path, robot_override=run.get("robot_override"))
    if task.config.task != "pick_place":
        raise RobocfgError(f"replay supports pick-place datasets; {task_path} is 'task: {task.config.task}'")
    params = task.config.pick_place
    setup = episode_setups(params, int(run["seed"]), ep.run_episode + 1)[ep.run_episode]
    layout = DatasetLayout(fps=info.fps, robot=info.robot, task_name=task_path.stem, state_names=(),
                           env_state_names=(), action_names=())
    from robocfg.datasets.recorder import EpisodeRecorder

    with World(task) as world:
        world.step(1)
        world.restore(world.snapshot())
        arm = world.robot.arm(run.get("arm"))
        sm = _StateMachine(world, arm, _Tools(None, None, None), params, setup, None, None)
        rec = EpisodeRecorder(world, arm, sm.obj, layout, None, lambda: "setup", replay_actions=ep.actions)
        rec.start()
        while world.steps < ep.physics_steps:
            world.step()
            rec.on_step()
        rec.stop()
        try:
            sm._check_placed()
            ok, reason = True, "placed"
        except MoveFailed as exc:
            ok, reason = False, f"{exc.phase}: {exc.reason}"
        pos = [float(v) for v in world.body_pose(sm.obj)[0]]
    rec_pos = ep.object_final[:3]
    dist = float(np.linalg.norm(np.subtract(pos, rec_pos)))
    return ReplayResult(k, ep.success, ok, reason, rec_pos, pos, dist, tolerance)
