"""``run trajectory``: a time-optimal joint trajectory through waypoints, tracked in PyBullet.

Steps: ``waypoints`` (resolve the task's entries to joint values, IK for Cartesian poses, check
joint limits) → ``planning`` (:func:`robocfg.motion.plan.plan_trajectory`: toppra along a spline,
or trapezoids stopping at every waypoint, or ruckig with a jerk limit) → ``check`` (resample at
1 kHz, count limit violations) → ``follow`` (the arm starts at the first waypoint; one command per
physics step; tracking error per joint). The result is plain data (JSON-ready) plus the sampled
trajectory (t, q, q̇, q̈) at ``sample_rate``.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path

import numpy as np

from robocfg.checks.task import CheckedTask
from robocfg.config.commands import TrajectoryParams
from robocfg.engine.dataset import EpisodeSink, ReplayScene
from robocfg.engine.registry import register_task
from robocfg.engine.runner import RunOutput, TaskRunner
from robocfg.errors import ConfigError, Problem, RobocfgError, RunFailed, RunInterrupted
from robocfg.runners.trajectory_command import TrajectoryCommand, TrajectoryOptions
from robocfg.runners.trajectory_report import Samples, TrajectoryResult, plot_result

CHECK_RATE = 1000.0  # Hz: resampling rate of the limit check


@register_task
class TrajectoryRunner(TrajectoryCommand, TaskRunner):
    params = TrajectoryParams
    report = TrajectoryResult

    def check(self) -> None:
        super().check()
        x = self.options.extras
        if isinstance(x, TrajectoryOptions) and x.no_sim:
            for flag, given in (("--record", self.options.record is not None), ("--dataset", x.dataset is not None)):
                if given:
                    raise ConfigError([Problem(flag, None, None, "", f"{flag} needs the simulation (drop --no-sim)")])

    def run(self) -> RunOutput:
        o, x = self.options, self.options.extras
        no_sim = isinstance(x, TrajectoryOptions) and x.no_sim
        result = run_trajectory(self.task, gui=o.gui, record=o.record, follow=not no_sim, arm=o.arm,
                                should_stop=o.should_stop, recording=o.recording, sink=o.sink,
                                seed=o.resolved_seed(self.task.config.sim.seed))
        if isinstance(x, TrajectoryOptions) and x.plot is not None:
            plot_result(result, x.plot)
        return RunOutput(result)

    @contextmanager
    def replay_scene(self, k: int) -> Iterator[ReplayScene]:
        """The world with the arm at the first waypoint, as the recording of the run (episode 0) began."""
        from robocfg.motion.trajectory import check_limits
        from robocfg.sim.world import World

        if k != 0:
            raise RobocfgError(f"a trajectory run is one episode (0); the dataset says {k}")
        _params, arm_cfg, names, limits, _wps, plan = plan_task(self.task, self.options.arm)
        passed = check_limits(plan.trajectory, limits, CHECK_RATE).total == 0
        with World(self.task) as world:
            _start(world, names, plan)
            yield ReplayScene(world, world.robot.arm(arm_cfg.name), None,
                              lambda: (passed, "ok" if passed else "limit violations"))


def _rounded(a: np.ndarray) -> list:
    """Plain lists for JSON, rounded to 1e-9 (shorter files, far below any error reported)."""
    return np.round(np.asarray(a, dtype=float), 9).tolist()


def plan_task(task: CheckedTask, arm_name: str | None = None):
    """Resolve the task's waypoints and plan (``arm_name`` overrides the task's ``arm``). Returns
    (params, arm config, joint names, limits, Waypoints, Plan). Raises ConfigError (bad
    waypoints/limits) or RunFailed (unreachable pose)."""
    from robocfg.motion.limits import limits_from_robot
    from robocfg.motion.plan import plan_trajectory
    from robocfg.motion.waypoints import resolve_waypoints

    params: TrajectoryParams = task.config.trajectory  # type: ignore[union-attr]
    robot = task.robots[0]
    arm = robot.config.arm(arm_name or params.arm)
    names = robot.arm_joints(arm)
    limits = limits_from_robot(robot, names, params.limits)
    home = np.asarray(arm.home, dtype=float)

    def problem(loc: tuple, msg: str):
        return task.doc.problem(("trajectory", "waypoints", *loc), msg)

    waypoints, note = _placed_waypoints(task, arm.name, params)
    wps = resolve_waypoints(waypoints, limits, home, problem, ik=_ik_fn(task, arm.name, params))
    plan = plan_trajectory(wps.q, limits, params.stop_at_waypoints, params.gridpoints)
    if note:
        plan.notes.insert(0, note)
    return params, arm, names, limits, wps, plan


def _placed_waypoints(task: CheckedTask, arm_name: str, params: TrajectoryParams) -> tuple[list, str]:
    """The waypoints, Cartesian ones moved to the running robot's arm for ``placement: auto``
    when it cannot reach them as written (``robocfg.motion.relative``); the line saying so."""
    from robocfg.config.types import Pose
    from robocfg.geometry import pose_matrix
    from robocfg.motion.relative import auto_map

    waypoints = list(params.waypoints)
    to_ee = _to_ee(task, arm_name, params)
    poses = [to_ee(pose_matrix(w)) for w in waypoints if isinstance(w, Pose)]
    if params.placement != "auto" or not poses:
        return waypoints, ""
    m = auto_map(task, arm_name, poses, "Cartesian waypoints", params.orientation_frame)
    if m is None:
        return waypoints, ""
    return [w.model_copy(update={"position": m.point(w.position)}) if isinstance(w, Pose) else w for w in waypoints], m.note


def _ik_fn(task: CheckedTask, arm_name: str, params: TrajectoryParams):
    from robocfg.config.types import Pose

    if not any(isinstance(w, Pose) for w in params.waypoints):
        return None
    from robocfg.geometry import pose_to_matrix
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import bound_ik_by_iterations

    mount = task.config.robots[0]
    model = KinematicModel.from_robot(task.robots[0], arm_name, base_pose=pose_to_matrix(mount.position, mount.quaternion_xyzw()))
    bound_ik_by_iterations(model)  # same waypoints ⇒ same joint values, whatever the machine load
    to_ee = _to_ee(task, arm_name, params)
    return lambda target, seed: model.ik(to_ee(target), seed_q=seed, frame="tcp")


def _to_ee(task: CheckedTask, arm_name: str, params: TrajectoryParams):
    """world_T_tcp for a Cartesian waypoint's pose (4x4) whose orientation is written in the
    task's ``orientation_frame`` (``robocfg.kinematics.frames.ee_rotation``)."""
    from robocfg.kinematics.frames import ee_rotation

    arm = task.robots[0].config.arm(arm_name)

    def to_ee(T: np.ndarray) -> np.ndarray:
        out = np.array(T, float)
        out[:3, :3] = ee_rotation(out[:3, :3], arm, params.orientation_frame)
        return out

    return to_ee


def run_trajectory(task: CheckedTask, gui: bool = False, record: Path | None = None,
                   follow: bool = True, fps: float = 15.0, arm: str | None = None,
                   should_stop=None, recording=None, sink: EpisodeSink | None = None,
                   seed: int = 0) -> TrajectoryResult:
    """Plan and (if ``follow``) track the task's trajectory. Raises ConfigError for bad input,
    RunFailed (with the result so far) if a phase fails; ``should_stop`` (SIGINT) ends the
    following early with the result marked ``interrupted``; ``recording``: the user's
    RecordSettings for ``record``; ``sink``: a dataset recording the run as episode 0 (stored with
    ``seed``)."""
    from robocfg.motion.trajectory import check_limits

    t_wall = time.perf_counter()
    params, arm_cfg, names, limits, wps, plan = plan_task(task, arm)
    check = check_limits(plan.trajectory, limits, CHECK_RATE)
    s = plan.trajectory.sample(params.sample_rate)
    result = TrajectoryResult(
        task=str(task.path), robot=task.robots[0].config.name, arm=arm_cfg.name, joint_names=list(names),
        method=plan.method, path=plan.path, stop_at_waypoints=params.stop_at_waypoints,
        duration=plan.duration, planning_time_ms=plan.planning_time * 1e3, gridpoints=plan.gridpoints,
        fit_factor=plan.fit_factor, waypoints=plan.waypoints.tolist(), waypoint_indices=list(plan.waypoint_indices),
        waypoint_kinds=[wps.kinds[i] for i in plan.waypoint_indices], waypoint_times=list(plan.waypoint_times),
        limits={"lower": limits.lower.tolist(), "upper": limits.upper.tolist(), "velocity": limits.velocity.tolist(),
                "acceleration": limits.acceleration.tolist(),
                "jerk": None if limits.jerk is None else limits.jerk.tolist()},
        limit_check=asdict(check) | {"total": check.total},
        samples=Samples(params.sample_rate, *(_rounded(a) for a in (s.t, s.q, s.qd, s.qdd))),
        warnings=[p.format() for p in task.warnings] + wps.warnings + list(plan.warnings), notes=list(plan.notes),
    )
    if wps.ik_errors:
        result.warnings += [f"waypoint {i}: IK residual {p * 1000:.2f} mm, {np.degrees(r):.2f}°"
                            for i, (p, r) in wps.ik_errors.items() if p > 1e-4 or r > 1e-3]
    if not follow:
        result.success = check.total == 0
        result.wall_time = time.perf_counter() - t_wall
        return result
    _follow(task, params, names, plan, result, gui, record, fps, should_stop, recording, sink, seed)
    result.wall_time = time.perf_counter() - t_wall
    return result


def _start(world, names: list[str], plan) -> None:
    """Put the arm at the trajectory's first waypoint, held there."""
    world.robot.reset_joints(names, plan.waypoints[0])
    world.robot.command_positions(names, plan.waypoints[0])


def _follow(task, params, names, plan, result: TrajectoryResult, gui, record, fps, should_stop, recording=None,
            sink: EpisodeSink | None = None, seed: int = 0) -> None:
    from robocfg.datasets.language import trajectory_instruction
    from robocfg.motion.follower import follow
    from robocfg.sim.record import Recorder
    from robocfg.sim.record_camera import CameraView
    from robocfg.sim.world import World

    with World(task, gui=gui) as world:
        world.should_stop = should_stop
        result.warnings += list(world.warnings)
        robot = world.robot
        _start(world, names, plan)
        recorder = None
        if record is not None:
            base = robot.base_pose()[:3, 3]
            view = CameraView(target=(float(base[0]) + 0.3, float(base[1]), float(base[2]) + 0.4), distance=1.5)
            recorder = Recorder(world, record, fps=fps, camera=view, settings=recording)
            recorder.capture()
        arm = robot.arm(result.arm)
        tap = None
        if sink is not None:  # the dataset records the run as episode 0, from the first waypoint on
            result.warnings.append("--dataset: the arm follows the recorded actions (joint targets at the dataset "
                                   "rate, ramped linearly between frames; the plan is sent one frame ahead to make up "
                                   "for the frame they lag), so the tracking error includes that ramp")
            tap = sink.begin(world, arm, None, lambda: "follow" if world.t < plan.duration else "settle",
                             ("follow", "settle"), trajectory_instruction(len(plan.waypoints)))
        try:
            tr = follow(world, names, plan.trajectory, params.settle_time,
                        on_step=recorder.maybe_capture if recorder is not None else None,
                        command=lambda q, qd: arm.command(q, qd),  # looked up per call: a dataset gates it
                        lead=tap.lag_steps if tap is not None else 0)
        except RunInterrupted:
            result.interrupted = True
            return
        except RunFailed as exc:
            if sink is not None and tap is not None:
                tap.stop()
                sink.end(tap, 0, seed, False, exc.phase, exc.reason)
                tap = None
            raise RunFailed(exc.phase, exc.reason, report=result) from None
        finally:
            if tap is not None:
                tap.stop()
            result.sim_time = world.t
            if recorder is not None:
                result.record = str(recorder.save())
        result.tracking = {
            "rms": tr.rms, "max": tr.max, "final": tr.final, "settled": tr.settled,
            "rms_per_joint": tr.rms_error, "max_per_joint": tr.max_error,
            "final_per_joint": tr.final_error, "settled_per_joint": tr.settled_error,
            "steps": tr.steps, "dt": world.dt, "settle_time": tr.settle_time,
        }
        result.measured = {"t": _rounded(tr.t), "q": _rounded(tr.q)}
        result.success = result.limit_check["total"] == 0
        if sink is not None and tap is not None:
            sink.end(tap, 0, seed, result.success, None if result.success else "check",
                     "ok" if result.success else "limit violations")
