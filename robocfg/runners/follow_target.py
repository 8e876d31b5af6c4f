"""``run follow-target``: the TCP follows a moving target while a QP keeps the arm clear of obstacles.

Loop, every control period (``control_rate``): target pose at ``t`` → joint state from the
simulator → :class:`~robocfg.motion.reactive.ReactiveController` step → position + velocity
targets for the arm drives → physics steps. Measured after each period: TCP position/orientation
error against the target at the same instant, robot–obstacle clearance (closest points),
robot–obstacle contacts (with penetration), and the controller's wall time.

Statistics skip the first ``settle_time`` seconds. A target not reached is reported with its
residual; the run fails (``RunFailed``, exit 1) only with ``require_reach``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.checks.task import CheckedTask
from robocfg.config.commands import FollowTargetParams, Motion
from robocfg.engine.dataset import EpisodeSink, ReplayScene
from robocfg.engine.options import RunOptions
from robocfg.engine.registry import register_task
from robocfg.engine.runner import RunOutput, TaskRunner
from robocfg.errors import RunFailed
from robocfg.geometry import euler_deg_to_quat_xyzw, quat_to_matrix
from robocfg.runners.follow_target_command import FollowTargetCommand, FollowTargetOptions
from robocfg.runners.follow_target_loop import FollowLoop
from robocfg.runners.follow_target_report import FINAL_WINDOW, FollowTargetResult, Stats

if TYPE_CHECKING:
    pass

__all__ = ["FollowTargetResult", "FollowTargetRunner", "Stats", "run_follow_target"]


@register_task
class FollowTargetRunner(FollowTargetCommand, TaskRunner):
    params = FollowTargetParams
    report = FollowTargetResult

    def check(self) -> None:
        super().check()
        from robocfg.errors import ConfigError, Problem

        x = self.options.extras
        if isinstance(x, FollowTargetOptions) and x.dataset is not None and self.options.gui:
            raise ConfigError([Problem("--dataset", None, None, "", "--dataset with --gui: a target dragged with "
                                       "the sliders is not recorded, so the run could not be replayed; drop --gui")])

    def run(self) -> RunOutput:
        o, x = self.options, self.options.extras
        assert isinstance(x, FollowTargetOptions)
        return RunOutput(run_follow_target(self.task, gui=o.gui, with_obstacle=x.with_obstacle, record=o.record,
                                           plot=x.plot, arm=o.arm, should_stop=o.should_stop, recording=o.recording,
                                           sink=o.sink, seed=o.resolved_seed(self.task.config.sim.seed)))

    @contextmanager
    def replay_scene(self, k: int) -> Iterator[ReplayScene]:
        """The run's world as its recording began (obstacles spawned, controller built, arm at home)."""
        from robocfg.errors import RobocfgError
        from robocfg.runners import follow_target_dataset

        if k != 0:
            raise RobocfgError(f"a follow-target run is one episode (0); the dataset says {k}")
        x = self.options.extras
        with_obstacle = x.with_obstacle if isinstance(x, FollowTargetOptions) else None
        params, _note, target = _placed_target(self.task, self.options.arm)
        use = params.with_obstacle if with_obstacle is None else with_obstacle
        with follow_target_dataset.replay_scene(
                self.task, lambda world: FollowLoop(self.task, world, params, target, RunOptions(arm=self.options.arm),
                                                    use)) as scene:
            yield scene


POSE_SAMPLES = 16  # target poses checked for reach over the run
JOINT_SPEED_SHARE = 0.8  # of the joint velocity limits a mapped motion may need (the rest: the servo's corrections)


def placed_params(task: CheckedTask, arm: str | None, params: FollowTargetParams) -> tuple[FollowTargetParams, str]:
    """``params`` with the motion (centre, radius, waypoints) and the obstacles (positions,
    sizes, motions) moved to the running robot's arm for ``placement: auto`` when it cannot reach
    the target as written (``robocfg.motion.relative``); the line saying so."""
    placed, note, _R = _placed(task, arm, params)
    return placed, note


def target_rotation(task: CheckedTask, arm: str | None, params: FollowTargetParams) -> tuple[np.ndarray, str]:
    """The target's rotation for the running arm's TCP frame (world_R_ee, 3×3): ``target_euler_deg``
    read in ``orientation_frame`` and, for ``tool_roll`` symmetric, turned half a turn about the tool
    axis when that is nearer the arm's home orientation (``robocfg.motion.orientation``); the line
    saying so (empty when not turned)."""
    from robocfg.motion.orientation import ee_target_rotation, home_rotation, resolved_tool_roll

    arm_cfg = task.robots[0].config.arm(arm)
    roll = resolved_tool_roll(params.tool_roll, arm_cfg)
    start = home_rotation(task, arm_cfg.name) if roll == "symmetric" else None
    R, turned = ee_target_rotation(quat_to_matrix(euler_deg_to_quat_xyzw(params.target_euler_deg)), arm_cfg,
                                   params.orientation_frame, roll, start)
    note = (f"tool_roll symmetric: the target orientation turned half a turn about the tool axis, nearer "
            f"{task.robots[0].config.name}'s home orientation (the gripper's two jaws look the same)") if turned else ""
    return R, note


def controller_margins(task: CheckedTask, arm: str | None, params: FollowTargetParams) -> Callable[[np.ndarray], bool]:
    """Whether the arm at joint values ``q`` (arm order, rad) keeps the reactive controller's
    margins: every self pair the controller watches (geometry under different arm joints, more
    than 2 x ``safety_margin`` apart at home) and every scene shape except the supports it stands
    on at least ``safety_margin − reach_tolerance`` apart (``robocfg.planning.checker``: the
    controller's pair rules and hulls). The controller holds such a pair at the margin and gives
    up TCP position instead; a pair up to ``reach_tolerance`` inside it costs about that much.
    Joint limits: IK answers lie within them already. The auto mapping asks this of each IK
    answer, so a scale the controller cannot track is not taken: on the IRB 7600 at x0.9 of the
    reach ratio IK put the upper arm 0.1 mm from the wrist (and through it, −4.1 mm) where the
    controller stalled at 20 mm (RMS 50 mm); at x0.95 the closest answer is 18.5 mm (tracked, RMS 2 mm)."""
    from robocfg.collision import robot_geometry
    from robocfg.geometry import pose_matrix
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.reactive.setup import scene_shapes
    from robocfg.planning.checker import CollisionChecker

    robot = task.robots[0]
    kin = KinematicModel.from_robot(robot, arm=robot.config.arm(arm).name, base_pose=pose_matrix(task.config.robots[0]))
    links, _missing = robot_geometry(robot)
    env, _meshes = scene_shapes(task.config.scene)
    checker = CollisionChecker(kin, links, env, params.safety_margin)  # pairs chosen as the controller does
    least = params.safety_margin - params.reach_tolerance
    return lambda q: checker.clearance(q) >= least


def _placed(task: CheckedTask, arm: str | None, params: FollowTargetParams) -> tuple[FollowTargetParams, str, np.ndarray]:
    """(``placed_params``'s answer, the target rotation of ``target_rotation``)."""
    from robocfg.motion.relative import PointMap, auto_map
    from robocfg.motion.targets import TargetMotion

    R, turned = target_rotation(task, arm, params)
    if params.placement != "auto":
        return params, turned, R
    target = TargetMotion(params.motion, R, params.orientation, math.radians(params.follow_angle_deg))
    poses = [target.pose(float(t)) for t in np.linspace(0.0, params.duration, POSE_SAMPLES)]
    m = auto_map(task, arm, poses, "the target's motion and obstacles", params.orientation_frame,
                 accept=controller_margins(task, arm, params))
    if m is None:
        return params, turned, R

    def motion(mo: Motion, pm: PointMap) -> Motion:
        return mo.model_copy(update={"center": pm.point(mo.center), "radius": pm.length(mo.radius),
                                     "waypoints": [pm.point(w) for w in mo.waypoints]})

    obstacles = [o.model_copy(update={"position": m.point(o.position), "size": [m.length(v) for v in o.size],
                                      "motion": None if o.motion is None else motion(o.motion, m)})
                 for o in params.obstacles]
    placed = params.model_copy(update={"motion": motion(params.motion, m), "obstacles": obstacles,
                                       "max_speed": m.length(params.max_speed)})
    paced, note = _paced(task, arm, placed, m.scale, m.note, R)
    return paced, "; ".join(n for n in (turned, note) if n), R


def _paced(task: CheckedTask, arm: str | None, params: FollowTargetParams, k: float, note: str,
           R: np.ndarray) -> tuple[FollowTargetParams, str]:
    """Times for a motion scaled ×k: kept (the same angular speed, TCP speeds and the speed cap ×k)
    while the arm's joints need at most ``JOINT_SPEED_SHARE`` of their velocity limits for it
    (``robocfg.motion.target_speed``); else stretched until they do. The note says which."""
    from robocfg.motion.target_speed import arm_joint_speed
    from robocfg.motion.targets import TargetMotion

    target = TargetMotion(params.motion, R, params.orientation, math.radians(params.follow_angle_deg))
    js = arm_joint_speed(task, arm, target, params.duration, params.velocity_scale)
    missed = f", {js.unreached} of {js.samples} sampled poses out of IK reach" if js.unreached else ""
    if js.share <= JOINT_SPEED_SHARE:
        return params, (f"{note}; times kept (the same angular speed): the target up to {js.tcp_speed:.2f} m/s, the joints "
                        f"at most {js.share:.0%} of their velocity limits{missed}")
    s = js.share / JOINT_SPEED_SHARE

    def slower(mo: Motion) -> Motion:
        return mo.model_copy(update={"period": mo.period * s, "waypoint_times": [t * s for t in mo.waypoint_times]})

    obstacles = [o if o.motion is None else o.model_copy(update={"motion": slower(o.motion)}) for o in params.obstacles]
    paced = params.model_copy(update={"motion": slower(params.motion), "obstacles": obstacles,
                                      "duration": params.duration * s})
    return paced, (f"{note}; times x{s:.2f} (period, waypoint times, duration): at the same angular speed the joints "
                   f"would need {js.share:.0%} of their velocity limits, now {JOINT_SPEED_SHARE:.0%}{missed}")


def _placed_target(task: CheckedTask, arm: str | None, params: FollowTargetParams | None = None):
    """(params moved for ``placement: auto``, the line saying so, the target's motion)."""
    from robocfg.motion.targets import TargetMotion

    params = params or task.config.follow_target  # type: ignore[union-attr]
    assert params is not None
    params, note, R = _placed(task, arm, params)
    target = TargetMotion(params.motion, R, params.orientation, math.radians(params.follow_angle_deg))
    return params, note, target


def run_follow_target(task: CheckedTask, gui: bool = False, with_obstacle: bool | None = None,
                      record: Path | None = None, plot: Path | None = None,
                      params: FollowTargetParams | None = None, realtime: bool | None = None,
                      arm: str | None = None, should_stop=None, recording=None, sink: EpisodeSink | None = None,
                      seed: int = 0) -> FollowTargetResult:
    """Run the follow-target task; returns the result, or raises RunFailed carrying it.

    ``with_obstacle`` overrides the task's switch; ``params`` overrides the task's
    ``follow_target`` block (benchmarks use it); ``realtime`` paces the loop to the wall clock
    (default: with ``gui``); ``should_stop`` (SIGINT) ends the loop early, the result marked
    ``interrupted``; ``recording``: the user's RecordSettings for ``record``; ``sink``: a dataset
    recording the run as episode 0 (stored with ``seed``; success = the target was reached).
    """
    from robocfg.runners import follow_target_dataset
    from robocfg.sim.world import World

    t_wall = time.perf_counter()
    params, note, target = _placed_target(task, arm, params)
    with World(task, gui=gui) as world:
        run = FollowLoop(task, world, params, target, RunOptions(gui=gui, record=record, arm=arm, should_stop=should_stop,
                                                                     recording=recording),
                         params.with_obstacle if with_obstacle is None else with_obstacle)
        tap = follow_target_dataset.begin(sink, world, run) if sink is not None else None
        try:
            run.loop(gui if realtime is None else realtime)
            result = run.finish(plot, t_wall)
        except RunFailed as exc:
            if tap is not None and sink is not None and isinstance(exc.report, FollowTargetResult):
                follow_target_dataset.end(sink, tap, seed, exc.report)
            raise
        finally:
            if tap is not None:
                tap.stop()
        if tap is not None and sink is not None and not result.interrupted:
            follow_target_dataset.end(sink, tap, seed, result)
    if note:
        result.warnings.insert(0, note)
    if not result.reached:
        tol = f"{params.reach_tolerance * 1000:.1f} mm / {math.degrees(params.orientation_tolerance):.2f} deg"
        e = result.position_error_mm
        at_rest = target.end_time <= params.duration - FINAL_WINDOW
        o = result.orientation_error_deg
        moving = ("" if e is None or at_rest else
                  f"RMS {e.rms:.1f} mm" + ("" if o is None else f" / {o.rms:.2f} deg (max {o.max:.1f} deg)") + " after settling, ")
        if result.tool_roll == "free":
            tol += " (tool axis)"
        msg = (f"target not reached within {tol}: {moving}residual {result.final_position_error_mm:.1f} mm / "
               f"{result.final_orientation_error_deg:.2f} deg ({result.unreachable_reason})")
        result.warnings.append(msg)
        if params.require_reach and not result.interrupted:
            result.failed_phase, result.reason = "track", msg
            raise RunFailed("track", msg, report=result)
    result.success = result.reached or not params.require_reach
    return result
