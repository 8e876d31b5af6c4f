"""``run gripper``: close and open the first arm's gripper, measure it, and test holding an object.

Phases: ``settle`` (home, gripper open) → per cycle ``close`` and ``open`` (each given
``hold_time``, plus ``1 / rate`` for the target ramp in smooth mode) → with ``hold_object``: ``place`` (object centred at the TCP on a static support),
``grasp`` (close), ``hold`` (support lowered by ``lift_support_by``; 0 removes it), ``release``
(open). Widths are measured from the finger geometry every step. A failed check raises
``RunFailed(phase, reason, report=result)``; the result is complete up to that phase.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from robocfg.checks.task import CheckedTask
from robocfg.config.commands import GripperParams
from robocfg.config.robot import ParallelGripperConfig
from robocfg.engine.registry import register_task
from robocfg.engine.runner import RunOutput, TaskRunner
from robocfg.errors import RobocfgError, RunFailed, RunInterrupted
from robocfg.runners.gripper_command import GripperCommand
from robocfg.runners.gripper_hold import hold_test, suction_test
from robocfg.runners.gripper_report import GripperResult, HoldTest, Move
from robocfg.runners.gripper_run import SETTLE_TIME, GripperRun

__all__ = ["GripperResult", "GripperRunner", "HoldTest", "Move", "run_gripper"]

WIDTH_CHANGE_MIN = 0.8  # fraction of (max_width − min_width) a free close/open must change the width by


@register_task
class GripperRunner(GripperCommand, TaskRunner):
    params = GripperParams
    report = GripperResult

    def check(self) -> None:
        super().check()
        robot_cfg = self.task.robots[0].config
        arm_cfg = robot_cfg.arm(self.options.arm)
        if arm_cfg.gripper is None:
            raise RobocfgError(f"robot {robot_cfg.name!r} has no gripper (arm {arm_cfg.name!r} gripper is missing "
                               f"in {self.task.robots[0].path})")

    def run(self) -> RunOutput:
        o = self.options
        return RunOutput(run_gripper(self.task, gui=o.gui, record=o.record, arm=o.arm, should_stop=o.should_stop,
                                     recording=o.recording))


def run_gripper(task: CheckedTask, gui: bool = False, record: Path | None = None,
                camera=None, fps: float = 10.0, arm: str | None = None, should_stop=None,
                recording=None) -> GripperResult:
    """Run the gripper task; returns the result or raises RunFailed carrying it. ``should_stop``
    (SIGINT) ends the run early with the result marked ``interrupted``; ``recording``: the user's
    RecordSettings for ``record``."""
    from robocfg.sim.record import Recorder
    from robocfg.sim.record_camera import facing_camera
    from robocfg.sim.world import World

    params: GripperParams = task.config.gripper  # type: ignore[union-attr]
    robot_cfg = task.robots[0].config
    arm_cfg = robot_cfg.arm(arm)
    g_cfg = arm_cfg.gripper
    if g_cfg is None:
        raise RobocfgError(f"robot {robot_cfg.name!r} has no gripper (arm {arm_cfg.name!r} gripper is missing in {task.robots[0].path})")
    t_wall = time.perf_counter()
    with World(task, gui=gui, visuals=record is not None) as world:  # visual meshes only to film
        world.should_stop = should_stop
        result = GripperResult(
            task=str(task.path), robot=robot_cfg.name, arm=arm_cfg.name, gripper_type=g_cfg.type,
            mode=params.mode, dt=world.dt, cycles=params.cycles,
            min_width=g_cfg.min_width if isinstance(g_cfg, ParallelGripperConfig) else 0.0,
            max_width=g_cfg.max_width if isinstance(g_cfg, ParallelGripperConfig) else 0.0)
        result.warnings = [p.format() for p in task.warnings] + list(world.warnings)
        recorder = None
        if record is not None:
            handle = world.robot.arm(arm_cfg.name)
            tcp = handle.tcp_pose()
            closing = tcp[:3, :3] @ np.asarray(handle.config.R_ee_graspnet)[1, :]  # grasp y in world
            view = camera or facing_camera(tcp[:3, 3], closing, world.robot.base_pose()[:3, 3], distance=0.35)
            recorder = Recorder(world, record, fps=fps, camera=view, settings=recording)
        run = GripperRun(world, params, result, recorder, arm_cfg.name)
        fingers = isinstance(g_cfg, ParallelGripperConfig)  # parallel and one-jaw: fingers that close
        if fingers:
            run.gripper.rate = params.rate if params.mode == "smooth" else None
        try:
            if fingers:
                _parallel(run)
            else:
                suction_test(run)
            result.success = True
        except RunInterrupted as exc:
            result.interrupted, result.failed_phase, result.reason = True, exc.phase, exc.reason
        except RunFailed as exc:
            result.failed_phase, result.reason = exc.phase, exc.reason
            raise RunFailed(exc.phase, exc.reason, report=result) from None
        finally:
            result.sim_time = world.t
            result.wall_time = time.perf_counter() - t_wall
            if recorder is not None:
                recorder.finish(result.success, "" if result.success else f"{result.failed_phase}: {result.reason}")
                result.record = str(recorder.save())
    return result


def _parallel(run: GripperRun) -> None:
    res, g = run.result, run.gripper
    run.run_for(SETTLE_TIME)
    travel = res.max_width - res.min_width
    for cycle in range(run.params.cycles):
        c = run.move("close", cycle, g.close)
        o = run.move("open", cycle, g.open)
        closed, opened = _measured(c.width_end, "close"), _measured(o.width_end, "open")
        res.final_closed_width, res.final_open_width = closed, opened
        res.width_change = change = opened - closed
        res.time_to_close = _worst(res.time_to_close, c.settle_time)
        res.time_to_open = _worst(res.time_to_open, o.settle_time)
        if c.settle_time is None:
            raise RunFailed("close", f"width still changing after {run.move_time():.2f} s (now {closed * 1000:.1f} mm)")
        if o.settle_time is None:
            raise RunFailed("open", f"width still changing after {run.move_time():.2f} s (now {opened * 1000:.1f} mm)")
        if change < WIDTH_CHANGE_MIN * travel:
            raise RunFailed("close", f"measured width changed by {change * 1000:.1f} mm, less than "
                                     f"{WIDTH_CHANGE_MIN:.0%} of max_width − min_width ({travel * 1000:.1f} mm)")
    if run.params.hold_object:
        hold_test(run)


def _measured(width: float | None, phase: str) -> float:
    """A finger gap (m) that a parallel gripper must report."""
    if width is None:
        raise RunFailed(phase, "the gripper reports no finger width")
    return width


def _worst(a: float | None, b: float | None) -> float | None:
    if b is None:
        return None if a is None else a
    return b if a is None else max(a, b)


