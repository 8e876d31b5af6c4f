"""``run grasp``: grasp planning from simulated depth cameras, then lift, shake and verify.

Episode k spawns ``objects[k % n]`` at a spot and yaw drawn with ``default_rng([seed, k])``
and runs :class:`robocfg.runners.grasp_episode._Episode` in the session's world, restored
before each episode (the gripper's box model is measured once, before the snapshot).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from robocfg.config.commands import GraspParams, Limits
from robocfg.config.robot import ParallelGripperConfig
from robocfg.datasets.language import grasp_instruction
from robocfg.engine.dataset import ReplayScene
from robocfg.engine.options import FrameRecorder, RunOptions
from robocfg.engine.randomize import place_randomly
from robocfg.engine.registry import register_task
from robocfg.engine.session import EpisodeSession, EpisodicRunner, episode_rng
from robocfg.errors import ConfigError, Problem, RobocfgError
from robocfg.motion.moves import bound_ik_by_iterations
from robocfg.runners.grasp_command import GraspCommand, GraspOptions
from robocfg.runners.grasp_episode import EpisodeFailed, EpisodeSetup, _Context, _Episode
from robocfg.runners.grasp_report import GraspEpisode, GraspReport, GraspTiming, summarise

__all__ = ["EpisodeFailed", "EpisodeSetup", "GraspRunner", "episode_setup", "episode_setups", "run_grasp"]


def episode_setup(params: GraspParams, seed: int, k: int) -> EpisodeSetup:
    """Episode k: ``objects[k % n]`` moved by ``randomize`` with ``default_rng([seed, k])``."""
    placed = place_randomly(params.objects[k % len(params.objects)], params.randomize, episode_rng(seed, k))
    return EpisodeSetup(k, seed + k, placed.body, placed.yaw)


def episode_setups(params: GraspParams, seed: int, episodes: int) -> list[EpisodeSetup]:
    return [episode_setup(params, seed, k) for k in range(episodes)]


class GraspSession(EpisodeSession[GraspEpisode]):
    """The grasp world, the measured gripper boxes, IK model and limits, shared by every episode."""

    # "settle": the spawned object comes to rest and is perceived; "recover": back home after a failed attempt
    phases = ("settle", "pre_grasp", "approach", "grasp", "lift", "shake", "recover")
    takes_pictures = True  # perception's depth camera sees the robot as drawn

    def __init__(self, task, options: RunOptions, on_cloud: Callable[[Any], None] | None = None):
        self.on_cloud = on_cloud  # called with the first processed object cloud
        super().__init__(task, options, GraspTiming())

    def prepare(self) -> None:
        from robocfg.grasp.gripper_model import measure_gripper

        self.params: GraspParams = self.task.config.grasp  # type: ignore[union-attr]
        self.arm_cfg = self.task.robots[0].config.arm(self.options.arm)
        handle = self.world.robot.arm(self.arm_cfg.name)
        if self.params.grip_force is not None:
            handle.require_gripper().set_force(self.params.grip_force)
        self.boxes = measure_gripper(self.world.robot, handle)  # moves the fingers: before the snapshot
        self.ctx = self._context()

    def _context(self) -> _Context:
        """What episodes share besides the world (none of it touches the physics)."""
        from robocfg.kinematics.model import KinematicModel
        from robocfg.motion.limits import limits_from_robot

        robot = self.task.robots[0]
        handle = self.world.robot.arm(self.arm_cfg.name)
        model = KinematicModel.from_robot(robot, arm=self.arm_cfg.name, base_pose=self.world.robot.base_pose())
        bound_ik_by_iterations(model)  # same seed ⇒ same answers, whatever the machine load
        scale = self.params.speed_scale
        assert isinstance(self.timing, GraspTiming)
        return _Context(world=self.world, arm=handle, params=self.params, model=model,
                        limits=limits_from_robot(robot, handle.joints, Limits(velocity_scale=scale, acceleration_scale=scale)),
                        shake_limits=limits_from_robot(robot, handle.joints, Limits()),
                        boxes=self.boxes, timing=self.timing, save_cloud=self.on_cloud)

    def _episode(self, k: int, recorder: FrameRecorder | None) -> _Episode:
        """Episode ``k`` in the restored world (it spawns the object)."""
        setup = episode_setup(self.params, self.seed, k)
        self.remove_after_episode(setup.body.name)
        return _Episode(self.ctx, setup, recorder, self.log_for(k))

    def episode(self, k: int, recorder: FrameRecorder | None) -> GraspEpisode:
        ep = self._episode(k, recorder)
        self.record_from(self.ctx.arm, ep.obj, lambda: "settle" if ep.mover.phase == "move" else ep.mover.phase,
                         lambda: grasp_instruction(ep.setup.body))
        return ep.run()

    def scene(self, k: int) -> ReplayScene:
        ep = self._episode(k, None)
        z0, lift = float(self.world.body_pose(ep.obj)[0][2]), self.params.lift_height

        def judge() -> tuple[bool, str]:
            """Held at the end and raised by half the lift height or more (from where it was spawned)."""
            rise = float(self.world.body_pose(ep.obj)[0][2]) - z0
            if ep.gripper.is_grasping(ep.obj) and rise >= 0.5 * lift:
                return True, "lifted"
            return False, f"object not held (rose {rise * 100:.1f} cm of {lift * 100:.0f})"

        return ReplayScene(self.world, self.ctx.arm, ep.obj, judge)

    def make_recorder(self, path: Any) -> FrameRecorder:
        from robocfg.grasp.draw import GraspRecorder
        from robocfg.sim.record_camera import CameraView

        view = CameraView(target=(0.5, 0.0, 0.08), distance=0.7, yaw_deg=50.0, pitch_deg=-30.0)
        return GraspRecorder(self.world, path, fps=12.0, camera=view, settings=self.options.recording)

    def report(self, records: list[GraspEpisode], interrupted: bool) -> GraspReport:
        from robocfg.grasp.perception import camera_warnings

        warnings = [w.format() for w in self.task.warnings] + camera_warnings(self.params)
        return GraspReport(task=str(self.task.path), robot=self.task.robots[0].config.name, arm=self.arm_cfg.name,
                           seed=self.seed, summary=summarise(records), episodes=records, warnings=warnings,
                           interrupted=interrupted)


def _cloud_saver(path: Path) -> Callable[[Any], None]:
    def save(cloud: Any) -> None:
        from robocfg.grasp.cloud import save_cloud

        save_cloud(cloud, path)

    return save


@register_task
class GraspRunner(GraspCommand, EpisodicRunner):
    params = GraspParams
    report = GraspReport

    def check(self) -> None:
        super().check()
        task = self.task
        params: GraspParams = task.config.grasp  # type: ignore[union-attr]
        if not params.objects:
            raise ConfigError([task.doc.problem(("grasp", "objects"), "no objects to grasp: give at least one")])
        robot = task.robots[0]
        arm_cfg = robot.config.arm(self.options.arm)
        if not isinstance(arm_cfg.gripper, ParallelGripperConfig):
            raise RobocfgError(f"run grasp plans two-finger antipodal grasps; arm {arm_cfg.name!r} of robot "
                               f"{robot.config.name!r} has a {arm_cfg.gripper.type if arm_cfg.gripper else 'no'!r} gripper")
        extras = self.options.extras
        if isinstance(extras, GraspOptions) and extras.save_cloud is not None \
                and extras.save_cloud.suffix.lower() not in (".npz", ".ply"):
            raise ConfigError([Problem("--save-cloud", None, None, "",
                                       f"needs a .npz or .ply file name, got {extras.save_cloud.name!r}")])

    def open_session(self) -> GraspSession:
        extras = self.options.extras
        on_cloud = self.on_cloud
        if on_cloud is None and isinstance(extras, GraspOptions) and extras.save_cloud is not None:
            on_cloud = _cloud_saver(extras.save_cloud)
        return GraspSession(self.task, self.options, on_cloud)

    on_cloud: Callable[[Any], None] | None = None  # overrides --save-cloud (Python callers)


def run_grasp(task, episodes: int = 1, seed: int | None = None, arm: str | None = None,
              record: Callable[[Any], FrameRecorder] | None = None, record_episode: int = 0,
              log: Callable[[str], None] | None = None, save_cloud: Callable[[Any], None] | None = None,
              on_episode: Callable[[GraspEpisode], None] | None = None,
              should_stop: Callable[[], bool] | None = None) -> tuple[GraspReport, GraspTiming]:
    """Keyword form of ``GraspRunner(task, RunOptions(...)).run()`` for scripts and benchmarks:
    (report, timing). ``save_cloud`` is called with the first processed cloud."""
    runner = GraspRunner(task, RunOptions(seed=seed, episodes=episodes, arm=arm, recorder=record,
                                          record_episode=record_episode, log=log, on_episode=on_episode,  # type: ignore[arg-type]
                                          should_stop=should_stop))
    runner.check()
    runner.on_cloud = save_cloud
    out = runner.run()
    assert isinstance(out.timing, GraspTiming)
    return out.report, out.timing
