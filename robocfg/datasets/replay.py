"""Re-simulate a stored episode (any kind that records datasets) from its recorded actions alone
and compare outcomes.

The episode's world is rebuilt by the task kind's runner from the task, arm and seed stored in
the dataset (``TaskRunner.replay_scene``: for pick-place the object pose, mass and friction of
episode k of seed s), then the recorded actions drive the robot through the same command gate as
when recording, for the same number of physics steps. The outcome matches when success is the
same and every object (a kind without one: the TCP) ends within ``tolerance`` (m) of its recorded
final position.
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
    """Recorded vs replayed: success, final positions (world, m; x y z per object, or the TCP's) and
    the largest distance between them (m)."""

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
    from robocfg.datasets.recorder import EpisodeRecorder
    from robocfg.engine import RunOptions, runner_for

    info, ep = read_info(root), read_episode(root, k)
    run = info.run
    task_path = Path(run.get("task_path", ""))
    if not task_path.is_file():
        raise RobocfgError(f"replay needs the task file the dataset was recorded from: {task_path} is missing")
    task = load_task(task_path, robot_override=run.get("robot_override"))
    runner = runner_for(task.config.task)(task, RunOptions(seed=int(run["seed"]), arm=run.get("arm")))
    layout = DatasetLayout(fps=info.fps, robot=info.robot, task_name=task_path.stem, state_names=(),
                           env_state_names=(), action_names=())
    with runner.replay_scene(ep.run_episode) as scene:
        world = scene.world
        rec = EpisodeRecorder(world, scene.arm, scene.obj, layout, None, lambda: "", replay_actions=ep.actions)
        rec.start()
        try:
            while world.steps < ep.physics_steps:
                world.step()
        finally:
            rec.stop()
        ok, reason = scene.judge()
        final = rec.final_pose()
    return ReplayResult(k, ep.success, ok, reason, positions(ep.object_final), positions(final),
                        farthest(ep.object_final, final), tolerance)


def positions(poses: list[float]) -> list[float]:
    """The positions (x, y, z per object, m) of poses stored as 7 values each."""
    return [float(v) for v in np.asarray(poses, float).reshape(-1, 7)[:, :3].reshape(-1)]


def farthest(recorded: list[float], replayed: list[float]) -> float:
    """The largest distance (m) between recorded and replayed positions: poses are 7 values each
    (position, quaternion), one per object (or the TCP's)."""
    a, b = np.asarray(recorded, float).reshape(-1, 7), np.asarray(replayed, float).reshape(-1, 7)
    if a.shape != b.shape:
        raise RobocfgError(f"the dataset stores {len(a)} final pose(s), the replay has {len(b)}")
    return float(np.linalg.norm(a[:, :3] - b[:, :3], axis=1).max())
