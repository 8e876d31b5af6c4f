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
from robocfg.config.scene import Body
from robocfg.engine.registry import register_task
from robocfg.engine.runner import RunOutput, TaskRunner
from robocfg.errors import RobocfgError, RunFailed, RunInterrupted
from robocfg.runners.gripper_report import GripperResult, HoldTest, Move, _mm

__all__ = ["GripperResult", "GripperRunner", "HoldTest", "Move", "run_gripper"]

SETTLE_TIME = 0.25  # s
SETTLE_TOL_FRACTION = 0.02  # of max_width − min_width, at least SETTLE_TOL_MIN
SETTLE_TOL_MIN = 0.001  # m
SETTLE_TAIL = 0.1  # s the width must stay within tolerance to count as settled
WIDTH_CHANGE_MIN = 0.8  # fraction of (max_width − min_width) a free close/open must change the width by
HOLD_DROP_MAX = 0.01  # m: the object may sink this much and still count as held
SUPPORT_LOWER_TIME = 0.5  # s
HOLD_WAIT = 0.5  # s after the support has gone


class _Run:
    def __init__(self, world, params: GripperParams, result: GripperResult, recorder, arm: str | None):
        self.world, self.params, self.result, self.recorder = world, params, result, recorder
        self.arm = world.robot.arm(arm)
        self.gripper = self.arm.gripper

    def width(self) -> float | None:
        return self.gripper.width()

    def phase(self, name: str) -> None:
        """Name the phase under way (recordings label their frames with it)."""
        if self.recorder is not None:
            self.recorder.set_phase(name)

    def run_for(self, seconds: float, each=None) -> float:
        """Step for ``seconds``; returns the worst mimic error seen."""
        w, worst = self.world, 0.0
        mimic = w.robot.mimic
        for _ in range(max(1, round(seconds / w.dt))):
            w.step()
            if each is not None:
                each()
            self.result.samples.append((round(w.t, 6), self.width()))
            if mimic is not None and mimic.pairs:
                worst = max(worst, mimic.max_error())
            if self.recorder is not None:
                self.recorder.maybe_capture()
        self.result.mimic_max_error = max(self.result.mimic_max_error, worst)
        return worst

    def move_time(self) -> float:
        """Time given to one close/open: ``hold_time``, plus the target ramp in smooth mode."""
        ramp = 1.0 / self.params.rate if self.params.mode == "smooth" and not self.gripper.grasps_at_surface else 0.0
        return self.params.hold_time + ramp

    def move(self, phase: str, cycle: int, command) -> Move:
        w, g = self.world, self.gripper
        t0, k0 = w.t, len(self.result.samples)
        w_start = self.width()
        self.phase(phase if self.params.cycles == 1 or phase not in ("close", "open") else f"{phase} {cycle + 1}")
        command()
        err = self.run_for(self.move_time())
        widths = [s[1] for s in self.result.samples[k0:]]
        w_end, settle = widths[-1], None
        if w_end is not None:
            travel = self.result.max_width - self.result.min_width
            tol = max(SETTLE_TOL_MIN, SETTLE_TOL_FRACTION * travel)
            outside = [k for k, v in enumerate(widths) if v is None or abs(v - w_end) > tol]
            if not outside:
                settle = w.dt
            elif (len(widths) - 1 - outside[-1]) * w.dt >= SETTLE_TAIL:
                settle = (outside[-1] + 1) * w.dt
        m = Move(phase, cycle, t0, w_start, w_end, settle, g.state(), err)
        self.result.moves.append(m)
        return m


@register_task
class GripperRunner(TaskRunner):
    kind = "gripper"
    params = GripperParams
    report = GripperResult
    summary = ("Close and open the gripper, then hold a cube. Reports measured widths, timing, mimic error and "
               "the hold test.")

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
    with World(task, gui=gui) as world:
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
        run = _Run(world, params, result, recorder, arm_cfg.name)
        fingers = isinstance(g_cfg, ParallelGripperConfig)  # parallel and one-jaw: fingers that close
        if fingers:
            run.gripper.rate = params.rate if params.mode == "smooth" else None
        try:
            if fingers:
                _parallel(run)
            else:
                _suction(run)
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


def _parallel(run: _Run) -> None:
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
        _hold_test(run)


def _measured(width: float | None, phase: str) -> float:
    """A finger gap (m) that a parallel gripper must report."""
    if width is None:
        raise RunFailed(phase, "the gripper reports no finger width")
    return width


def _worst(a: float | None, b: float | None) -> float | None:
    if b is None:
        return None if a is None else a
    return b if a is None else max(a, b)


def _place_object(run: _Run, at: np.ndarray, R: np.ndarray):
    """Move the hold object to ``at`` with rotation ``R`` on a static support; returns (name, body, support Body)."""
    from robocfg.geometry import matrix_to_quat

    w, name = run.world, run.params.hold_object
    if name is None:
        raise RunFailed("place", "no gripper.hold_object to place")
    spec = next((b for b in w.task.config.scene.objects if b.name == name), None)
    if spec is None:
        known = [b.name for b in w.task.config.scene.objects]
        raise RunFailed("place", f"hold_object {name!r} is not in scene.objects (known: {', '.join(known) or 'none'})")
    w.set_body_pose(name, at, matrix_to_quat(R))
    bottom = at[2] - _half_extent_z(w, name)
    top_size = 0.6 * min(_footprint(spec))
    support = Body(name="_support", shape="box", size=[top_size, top_size, max(bottom, 0.01)], mass=0.0,
                   color=[0.4, 0.4, 0.45, 1.0], position=[float(at[0]), float(at[1]), bottom - max(bottom, 0.01) / 2])
    w.add_body(support, static=True)
    return name, support


def _grasp_centre(run: _Run, tcp: np.ndarray) -> np.ndarray:
    """Where the hold object's centre goes: the TCP, moved across by ``grasp_side_shift`` at the
    object's width along the closing direction (a one-jaw gripper holds it against its fixed jaw)."""
    from robocfg.kinematics.frames import grasp_side_shift

    cfg = run.arm.config
    spec = next((b for b in run.world.task.config.scene.objects if b.name == run.params.hold_object), None)
    closing_ee = np.asarray(cfg.R_ee_graspnet, float)[1]
    if spec is None:
        return tcp[:3, 3]
    k = int(np.argmax(np.abs(closing_ee)))
    width = float(spec.size[k]) if spec.shape == "box" else 2 * float(spec.size[0])
    return tcp[:3, 3] + grasp_side_shift(cfg, width) * (tcp[:3, :3] @ closing_ee)


def _half_extent_z(world, name: str) -> float:
    lo, hi = world.aabb(name)
    return float(hi[2] - lo[2]) / 2


def _footprint(b: Body) -> list[float]:
    if b.shape in ("box", "mesh"):
        return [b.size[0], b.size[1]]
    return [2 * b.size[0], 2 * b.size[0]]


def _lower_support(run: _Run, support: Body) -> None:
    w, by = run.world, run.params.lift_support_by
    if by <= 0:
        w.remove_body(support.name)
        return
    x, y, z0 = support.position
    n = max(1, round(SUPPORT_LOWER_TIME / w.dt))
    k = [0]

    def lower() -> None:
        k[0] += 1
        w.set_body_pose(support.name, [x, y, z0 - by * min(1.0, k[0] / n)])

    run.run_for(SUPPORT_LOWER_TIME, each=lower)


def _hold_test(run: _Run) -> None:
    w, g, res = run.world, run.gripper, run.result
    tcp = run.arm.tcp_pose()
    name, support = _place_object(run, _grasp_centre(run, tcp), run.arm.ee_pose()[:3, :3])
    run.run_for(SETTLE_TIME)
    run.move("grasp", 0, g.close)
    grasp_before = g.is_grasping(name)
    width_on = run.width()
    z0 = w.body_pose(name)[0][2]
    hold = HoldTest(name, run.params.lift_support_by, grasp_before, False, width_on, 0.0, False, False)
    res.hold = hold
    if not grasp_before:
        raise RunFailed("grasp", f"the fingers do not both touch {name!r} after closing (width {_mm(width_on)})")
    _lower_support(run, support)
    run.phase("hold")
    run.run_for(HOLD_WAIT)
    hold.drop = float(z0 - w.body_pose(name)[0][2])
    hold.grasping_after = g.is_grasping(name)
    hold.held = hold.grasping_after and hold.drop < HOLD_DROP_MAX
    if not hold.held:
        raise RunFailed("hold", f"{name!r} was not held: it sank {hold.drop * 1000:.1f} mm "
                                f"(limit {HOLD_DROP_MAX * 1000:.0f} mm), fingers touching: {hold.grasping_after}")
    run.move("release", 0, g.open)
    hold.released = not g.is_grasping(name)
    if not hold.released:
        raise RunFailed("release", f"{name!r} still between both fingers after opening")


def _suction(run: _Run) -> None:
    """Suction: the object is placed against the cup, suction on, support lowered, suction off."""
    w, g, res = run.world, run.gripper, run.result
    run.run_for(SETTLE_TIME)
    if not run.params.hold_object:
        raise RunFailed("place", "a suction gripper needs gripper.hold_object to test")
    cup = run.world.robot.link_pose(g.config.link)
    name = run.params.hold_object
    down = cup[:3, 2]  # the cup's z axis points out of the cup face
    w.set_body_pose(name, cup[:3, 3])  # provisional, then push it out by its half extent
    at = cup[:3, 3] + down * _half_extent_z(w, name)
    name, support = _place_object(run, at, np.eye(3))
    run.run_for(SETTLE_TIME)
    z0 = w.body_pose(name)[0][2]
    run.move("grasp", 0, g.on)
    hold = HoldTest(name, run.params.lift_support_by, g.is_grasping(name), False, None, 0.0, False, False)
    res.hold = hold
    if not hold.grasping_before:
        raise RunFailed("grasp", f"suction did not attach {name!r}")
    _lower_support(run, support)
    run.phase("hold")
    run.run_for(HOLD_WAIT)
    hold.drop = float(z0 - w.body_pose(name)[0][2])
    hold.grasping_after = g.is_grasping(name)
    hold.held = hold.grasping_after and hold.drop < HOLD_DROP_MAX
    if not hold.held:
        raise RunFailed("hold", f"{name!r} was not held (sank {hold.drop * 1000:.1f} mm)")
    run.move("release", 0, g.off)
    hold.released = not g.is_grasping(name)
