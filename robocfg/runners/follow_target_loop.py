"""The follow-target control loop in a built world: obstacles spawned, the reactive controller
built, then one QP step per control period with the errors, clearance and contacts measured after
it. Frames: world, m, rad; the series are (t s, position error m, orientation error rad,
clearance m) per control step.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from robocfg.checks.task import CheckedTask
from robocfg.config.commands import FollowObstacle, FollowTargetParams
from robocfg.config.scene import Body
from robocfg.config.types import AXIS_INDEX
from robocfg.engine.options import RunOptions
from robocfg.errors import RunFailed, RunInterrupted
from robocfg.geometry import rotation_angle
from robocfg.runners.follow_target_report import FollowTargetResult, plot_series, summarise

if TYPE_CHECKING:
    from robocfg.motion.targets import TargetMotion
    from robocfg.sim.world import World

CLEARANCE_QUERY = 0.5  # m: clearances beyond this are reported as this value
DEFAULT_OBSTACLE_SIZE = 0.05  # m: radius of the sphere added when with_obstacle has no obstacles listed
GUI_SLIDER_RANGE = 0.4  # m either side of the initial target
ENVIRONMENT = ("ground", "table", "pedestal")  # scene bodies counted as environment contacts


class FollowLoop:
    """One follow-target run in a built world: obstacles spawned, controller built, then ``loop``."""

    def __init__(self, task: CheckedTask, world: World, params: FollowTargetParams, target: TargetMotion,
                 options: RunOptions, use_obstacle: bool):
        self.task, self.world, self.params, self.target = task, world, params, target
        world.should_stop = options.should_stop
        self.arm = world.robot.arm(options.arm)
        from robocfg.motion.orientation import resolved_tool_roll

        roll = resolved_tool_roll(params.tool_roll, self.arm.config)
        self.free_roll = roll == "free"
        self.n_sub = max(1, round(1.0 / (params.control_rate * world.dt)))
        self.ctrl_dt = self.n_sub * world.dt
        obstacles = _obstacles(params, use_obstacle, self.arm.tcp_pose()[:3, 3], target.position(0.0))
        self.result = r = FollowTargetResult(
            task=str(task.path), robot=task.robots[0].config.name, arm=self.arm.config.name, motion=params.motion.type,
            orientation=params.orientation, with_obstacle=use_obstacle,
            obstacles=[o.name for o in task.config.scene.obstacles] + [o.name for o in obstacles],
            duration=params.duration, control_rate=1.0 / self.ctrl_dt, safety_margin=params.safety_margin,
            settle_time=params.settle_time, tool_roll=roll)
        r.warnings = [p.format() for p in task.warnings] + list(world.warnings)
        if abs(1.0 / self.ctrl_dt - params.control_rate) > 0.01 * params.control_rate:
            r.warnings.append(f"control_rate {params.control_rate:g} Hz is not a divisor of the physics rate "
                              f"{1.0 / world.dt:g} Hz: running at {1.0 / self.ctrl_dt:g} Hz ({self.n_sub} physics steps)")
        self.moving = self._spawn(obstacles)
        self.ctrl = self._controller(obstacles)
        self.obstacle_ids = {n: world.bodies[n] for n in r.obstacles if n in world.bodies}
        self.base_links = _base_links(task, world)
        self.env_ids = {n: world.bodies[n] for n in ENVIRONMENT if n in world.bodies}
        self.in_contact = False
        self._start_warnings()
        self.marker = world.add_marker([float(v) for v in target.position(0.0)])
        world.bodies["_target"] = self.marker
        self.sliders = _Sliders(world, target.position(0.0)) if options.gui else None
        self.recorder = None
        if options.record is not None:
            from robocfg.sim.record import Recorder
            from robocfg.sim.record_camera import CameraView

            c = target.center
            view = CameraView(target=(float(c[0]) * 0.6, float(c[1]), float(c[2]) * 0.8), distance=1.5,
                              yaw_deg=60.0, pitch_deg=-25.0)
            self.recorder = Recorder(world, options.record, fps=15.0, camera=view, settings=options.recording)
        self.series: list[tuple[float, float, float, float]] = []
        self.times: list[float] = []
        self.cpu: list[float] = []

    def _spawn(self, obstacles: list[FollowObstacle]) -> dict[str, tuple[TargetMotion, np.ndarray]]:
        """Spawn the obstacles (static bodies); the moving ones with their motion and pose."""
        from robocfg.geometry import pose_matrix
        from robocfg.motion.targets import TargetMotion

        moving: dict[str, tuple[TargetMotion, np.ndarray]] = {}
        for ob in obstacles:
            body = Body(name=ob.name, shape=ob.shape, size=list(ob.size), mass=0.0, color=list(ob.color),
                        position=list(ob.position), quat_xyzw=list(ob.quaternion_xyzw()))
            self.world.add_body(body, static=True)
            if ob.motion is not None:
                moving[ob.name] = (TargetMotion(ob.motion), pose_matrix(ob))
                self.world.set_body_pose(ob.name, moving[ob.name][0].position(0.0), ob.quaternion_xyzw())
        return moving

    def _controller(self, obstacles: list[FollowObstacle]) -> Any:
        from robocfg.motion.reactive import EscapeSettings, ReactiveController, ReactiveSettings
        from robocfg.motion.reactive.setup import MeshPoses, arm_spec, body_shape, scene_shapes
        from robocfg.sim.loading import prepared_urdf

        p, checked = self.params, self.task.robots[0]
        env, skipped = scene_shapes(self.task.config.scene, MeshPoses.of(self.world))
        for name in skipped:
            self.result.warnings.append(f"obstacle {name!r} is a mesh: the controller does not avoid it (only measured)")
        for ob in obstacles:
            shape = body_shape(ob)
            if shape is None:  # obstacles are primitives; only scene meshes have no shape
                continue
            if ob.name in self.moving:
                shape.pose[:3, 3] = self.moving[ob.name][0].position(0.0)
            env.append(shape)
        spec = arm_spec(checked, prepared_urdf(checked), self.world.robot.base_pose(), self.arm.config.name,
                        p.acceleration, p.velocity_scale)
        settings = ReactiveSettings(dt=self.ctrl_dt, margin=p.safety_margin, gain=p.gain,
                                    max_linear_speed=p.max_speed, posture_weight=p.posture_weight,
                                    self_collision=p.self_collision, escape=EscapeSettings(enabled=p.escape),
                                    free_roll=self.free_roll)
        ctrl = ReactiveController(spec, env, settings)
        ctrl.reset(self.arm.joint_positions())
        self.result.collision_pairs = len(ctrl.pairs)
        return ctrl

    # ---- the control loop ------------------------------------------------------------------
    def loop(self, realtime: bool) -> None:
        """Control steps until ``duration``, the GUI closed, a failure (kept in the result) or a stop."""
        from robocfg.sim.queries import GUI_ERROR

        w, r = self.world, self.result
        dragged = None
        try:
            for _ in range(max(1, round(self.params.duration / self.ctrl_dt))):
                t = w.t
                self._move_obstacles(t + self.ctrl_dt)
                try:
                    dragged = self.sliders.read(dragged) if self.sliders is not None else None
                    q_now = self.arm.joint_positions()
                except GUI_ERROR:  # the GUI window was closed
                    r.warnings.append(f"GUI closed at t = {w.t:.2f} s: run stopped")
                    break
                T_goal, v_goal = _goal(self.target, t, dragged)  # now: the controller steps to t + ctrl_dt
                res = self.ctrl.step(T_goal, q_measured=q_now, velocity=v_goal)
                self.times.append(res.solve_time)
                self.cpu.append(res.cpu_time)
                if res.blocked:
                    r.blocked_time += self.ctrl_dt
                q_cmd = drive_target(res.q, res.dq, self.ctrl_dt, self.n_sub)
                self.arm.command(q_cmd + self.lead * res.dq if self.lead else q_cmd, res.dq)
                t_step = time.perf_counter()
                w.step(self.n_sub)
                self._measure(dragged)
                if realtime:
                    time.sleep(max(0.0, self.ctrl_dt - (time.perf_counter() - t_step)))
        except RunInterrupted:
            r.interrupted = True
        except RunFailed as exc:
            r.failed_phase, r.reason = exc.phase, exc.reason
            self.failure = exc

    failure: RunFailed | None = None
    lead = 0.0  # s: joint targets sent this far ahead along the QP's velocity (a dataset's gate lag)

    def _move_obstacles(self, t: float) -> None:
        for name, (m, T_ob) in self.moving.items():
            T_ob[:3, 3] = m.position(t)
            self.world.set_body_pose(name, T_ob[:3, 3], self.world.body_pose(name)[1])
            self.ctrl.set_obstacle_pose(name, T_ob, m.velocity(t)[:3])

    def _measure(self, dragged: np.ndarray | None) -> None:
        """Errors against the target now, clearance and contacts after one control period."""
        w, r = self.world, self.result
        T_goal, _ = _goal(self.target, w.t, dragged)
        w.set_body_pose(self.marker, T_goal[:3, 3])
        tcp = self.arm.tcp_pose()
        e_pos = float(np.linalg.norm(tcp[:3, 3] - T_goal[:3, 3]))
        if self.free_roll:
            from robocfg.motion.reactive.tool_roll import axis_angle

            e_rot = axis_angle(tcp[:3, :3], T_goal[:3, :3], AXIS_INDEX[self.arm.config.ee_axis])
        else:
            e_rot = rotation_angle(tcp[:3, :3], T_goal[:3, :3])
        clearance = math.inf
        if self.obstacle_ids:
            clearance, link, obst = self._clearance()
            if r.min_clearance_mm is None or clearance * 1000 < r.min_clearance_mm:
                r.min_clearance_mm = clearance * 1000
                r.min_clearance_link, r.min_clearance_obstacle = link, obst
            touching = self._touching(self.obstacle_ids)
            r.contact_steps += touching
            r.contacts += touching and not self.in_contact
            self.in_contact = touching
        if self.env_ids and self._touching(self.env_ids):
            r.environment_contact_steps += 1
        self.series.append((w.t, e_pos, e_rot, clearance))
        if self.recorder is not None:
            self.recorder.maybe_capture()

    def _clearance(self) -> tuple[float, str | None, str | None]:
        """(distance m, robot link, obstacle) of the closest robot–obstacle pair (CLEARANCE_QUERY if none is closer)."""
        robot = self.world.robot
        best: tuple[float, str | None, str | None] = (CLEARANCE_QUERY, None, None)
        for name, bid in self.obstacle_ids.items():
            for c in self.world.closest_points(robot.body_id, bid, CLEARANCE_QUERY):
                if c.distance < best[0]:
                    best = (c.distance, robot.link_name(c.link_a), name)
        return best

    def _touching(self, bodies: dict[str, int]) -> bool:
        """Any penetrating contact between a moving robot link (not the base nor a link fixed to
        it) and ``bodies``."""
        robot = self.world.robot.body_id
        return any(c.distance < 0.0 and c.link_a not in self.base_links
                   for bid in bodies.values() for c in self.world.contact_points(robot, bid))

    def _start_warnings(self) -> None:
        margin, robot = self.params.safety_margin, self.world.robot
        for name, bid in self.obstacle_ids.items():
            pts = self.world.closest_points(robot.body_id, bid, margin)
            if not pts:
                continue
            c = min(pts, key=lambda c: c.distance)
            link = robot.link_name(c.link_a)
            if c.distance < 0:
                self.result.warnings.append(f"obstacle {name!r} overlaps robot link {link!r} at the start by "
                                            f"{-c.distance * 1000:.1f} mm: collision constraints are relaxed until "
                                            "the robot is clear")
            else:
                self.result.warnings.append(f"obstacle {name!r} is {c.distance * 1000:.1f} mm from robot link {link!r} "
                                            f"at the start, inside the safety margin ({margin * 1000:.0f} mm)")

    def finish(self, plot: Path | None, t_wall: float) -> FollowTargetResult:
        """Statistics, recording and plot; re-raises a failure with the result attached."""
        r = self.result
        summarise(r, self.series, self.times, self.cpu, self.params, self.ctrl)
        r.sim_time = self.world.t
        if self.recorder is not None:
            r.record = str(self.recorder.save())
        if plot is not None and self.series:
            r.plot = str(plot_series(plot, self.series, r, self.params))
        r.wall_time = time.perf_counter() - t_wall
        if self.failure is not None:
            raise RunFailed(self.failure.phase, self.failure.reason, report=r) from None
        return r


def _base_links(task: CheckedTask, world: World) -> set[int]:
    """PyBullet link indices of the robot's base (-1) and of every link joined to it by fixed
    joints only: they do not move, so their contact with the ground they stand on is no robot
    contact (the example-robot-data UR10's ``base_link`` hangs under a ``world`` root by a fixed
    joint and counted every step)."""
    urdf = task.robots[0].urdf
    out = {-1}
    for name, index in world.robot.link_index.items():
        link, rigid = name, True
        while rigid and (joint := urdf.joint_to_child(link)) is not None:
            rigid, link = joint.type == "fixed", joint.parent
        if rigid:
            out.add(index)
    return out


def drive_target(q_end: np.ndarray, dq: np.ndarray, ctrl_dt: float, n_sub: int) -> np.ndarray:
    """The drives' position target (rad) for a control period that ends at ``q_end`` moving at
    ``dq`` (rad/s) over ``n_sub`` physics steps.

    PyBullet's joint motor sets each physics step's velocity to ``dq + kp·(target − q)/h`` (with
    the drives' velocity gain 1, ``btMultiBodyJointMotor``), so a target at the period's *end*
    adds a correction of ``kp·Δ`` on top of the feed-forward every step and the joint settles one
    step *ahead* of the command. A joint on the ramp stays on it when the target is the ramp's
    position at the start of the physics step; over ``n_sub`` steps the target is held, so the
    ramp's mean over those starts: ``q_end − dq·h·(n_sub + 1)/2`` with ``h = ctrl_dt / n_sub``.
    """
    h = ctrl_dt / n_sub
    return np.asarray(q_end, float) - np.asarray(dq, float) * h * (n_sub + 1) / 2


def _obstacles(params: FollowTargetParams, with_obstacle: bool, start: np.ndarray, goal: np.ndarray) -> list[FollowObstacle]:
    if not with_obstacle:
        return []
    if params.obstacles:
        return list(params.obstacles)
    mid = (start + goal) / 2  # nothing listed: a sphere halfway between the start TCP and the target
    return [FollowObstacle(name="obstacle", shape="sphere", size=[DEFAULT_OBSTACLE_SIZE], position=[float(v) for v in mid])]


def _goal(target: TargetMotion, t: float, dragged: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    T = target.pose(t)
    if dragged is not None:
        T[:3, 3] = dragged
        return T, np.zeros(6)
    return T, target.velocity(t)


class _Sliders:
    """GUI sliders for the target position: moving one switches to the slider target."""

    def __init__(self, world: World, position: np.ndarray):
        self.world = world
        self.ids = [(world.add_slider(f"target {axis} (m)", float(v) - GUI_SLIDER_RANGE, float(v) + GUI_SLIDER_RANGE,
                                      float(v)), float(v)) for axis, v in zip("xyz", position, strict=True)]

    def read(self, dragged: np.ndarray | None) -> np.ndarray | None:
        values = np.array([self.world.read_slider(sid) for sid, _ in self.ids])
        if dragged is None and np.all(np.abs(values - np.array([v for _, v in self.ids])) < 1e-9):
            return None
        return values
