"""``run follow-target``: the TCP follows a moving target while a QP keeps the arm clear of obstacles.

Loop, every control period (``control_rate``): target pose at ``t`` → joint state from PyBullet →
:class:`~robocfg.motion.reactive.ReactiveController` step → position + velocity targets for the
arm drives → physics steps. Measured after each period: TCP position/orientation error against
the target at the same instant, robot–obstacle clearance (PyBullet ``getClosestPoints``),
robot–obstacle contacts (``getContactPoints`` with penetration), and the controller's wall time.

Statistics skip the first ``settle_time`` seconds. A target not reached (see :func:`_reached`) is
reported with its residual; the run fails (``RunFailed``, exit 1) only with ``require_reach``.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from robocfg.checks.task import CheckedTask
from robocfg.config.commands import FollowObstacle, FollowTargetParams
from robocfg.config.scene import Body
from robocfg.errors import RunFailed
from robocfg.geometry import euler_deg_to_quat_xyzw, rotation_angle
from robocfg.runners.report_schema import REPORT_SCHEMA_VERSION

CLEARANCE_QUERY = 0.5  # m: clearances beyond this are reported as this value
SAMPLE_RATE = 60.0  # Hz of the samples kept in the result
FINAL_WINDOW = 0.25  # s averaged for the final (residual) error
DEFAULT_OBSTACLE_SIZE = 0.05  # m: radius of the sphere added when with_obstacle has no obstacles listed
GUI_SLIDER_RANGE = 0.4  # m either side of the initial target


@dataclass
class Stats:
    """mean / RMS / max of a series (units in the field name of the owner)."""

    mean: float
    rms: float
    max: float

    @classmethod
    def of(cls, values: np.ndarray) -> Stats | None:
        if len(values) == 0:
            return None
        v = np.asarray(values, float)
        return cls(float(v.mean()), float(np.sqrt((v * v).mean())), float(v.max()))


@dataclass
class FollowTargetResult:
    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)  # of the --json report
    task: str
    robot: str
    arm: str
    motion: str
    orientation: str
    with_obstacle: bool
    obstacles: list[str]
    duration: float  # s
    control_rate: float  # Hz (actual: physics rate / substeps)
    safety_margin: float  # m
    settle_time: float  # s
    success: bool = False
    position_error_mm: Stats | None = None  # after settling
    orientation_error_deg: Stats | None = None
    final_position_error_mm: float = math.nan  # residual, mean of the last FINAL_WINDOW
    final_orientation_error_deg: float = math.nan
    reached: bool = False
    unreachable_reason: str | None = None
    min_clearance_mm: float | None = None  # robot–obstacle, PyBullet closest points (None: no obstacle)
    min_clearance_link: str | None = None
    min_clearance_obstacle: str | None = None
    contacts: int = 0  # robot–obstacle contact events (steps entering contact)
    contact_steps: int = 0  # control steps with robot–obstacle penetration
    environment_contact_steps: int = 0  # control steps with robot–ground/table/pedestal penetration
    step_time_median_ms: float = math.nan  # controller wall time per control step
    step_time_p95_ms: float = math.nan
    step_cpu_median_ms: float = math.nan  # CPU time per control step (unaffected by other processes)
    step_cpu_p95_ms: float = math.nan
    steps: int = 0
    soft_steps: int = 0  # steps solved with relaxed collision constraints
    fallback_steps: int = 0  # steps where the QP failed: zero velocity commanded
    escapes: int = 0  # local-minimum escapes started
    blocked_time: float = 0.0  # s spent at the safety margin (model distance) while off target
    collision_pairs: int = 0
    samples: list[tuple[float, float, float, float | None]] = field(default_factory=list)  # (t s, pos mm, rot deg, clearance mm)
    warnings: list[str] = field(default_factory=list)
    failed_phase: str | None = None
    reason: str | None = None
    sim_time: float = 0.0
    wall_time: float = 0.0
    record: str | None = None
    plot: str | None = None

    def to_dict(self) -> dict:
        return asdict(self)


def _euler_matrix(rpy_deg) -> np.ndarray:
    from robocfg.geometry import quat_to_matrix

    return quat_to_matrix(euler_deg_to_quat_xyzw(rpy_deg))


def _obstacles(params: FollowTargetParams, with_obstacle: bool, start: np.ndarray, goal: np.ndarray) -> list[FollowObstacle]:
    if not with_obstacle:
        return []
    if params.obstacles:
        return list(params.obstacles)
    mid = (start + goal) / 2  # nothing listed: a sphere halfway between the start TCP and the target
    return [FollowObstacle(name="obstacle", shape="sphere", size=[DEFAULT_OBSTACLE_SIZE], position=[float(v) for v in mid])]


class _Probe:
    """PyBullet measurements: closest robot–obstacle distance and contacts."""

    def __init__(self, world, obstacles: dict[str, int], environment: dict[str, int]):
        import pybullet as p

        self.p, self.world = p, world
        self.robot = world.robot
        self.obstacles, self.environment = obstacles, environment
        self.in_contact = False

    def clearance(self) -> tuple[float, str | None, str | None]:
        """(distance m, robot link, obstacle) of the closest robot–obstacle pair (CLEARANCE_QUERY if none is closer)."""
        best = (CLEARANCE_QUERY, None, None)
        for name, bid in self.obstacles.items():
            for c in self.p.getClosestPoints(self.robot.body_id, bid, CLEARANCE_QUERY, physicsClientId=self.world.client):
                if c[8] < best[0]:
                    best = (float(c[8]), self.robot.link_name(c[3]), name)
        return best

    def contacts(self, bodies: dict[str, int]) -> bool:
        """Any penetrating contact between a moving robot link (not the base) and ``bodies``."""
        for bid in bodies.values():
            for c in self.p.getContactPoints(self.robot.body_id, bid, physicsClientId=self.world.client):
                if c[8] < 0.0 and c[3] != -1:
                    return True
        return False


def run_follow_target(task: CheckedTask, gui: bool = False, with_obstacle: bool | None = None,
                      record: Path | None = None, plot: Path | None = None,
                      params: FollowTargetParams | None = None, realtime: bool | None = None) -> FollowTargetResult:
    """Run the follow-target task; returns the result, or raises RunFailed carrying it.

    ``with_obstacle`` overrides the task's switch; ``params`` overrides the task's
    ``follow_target`` block (benchmarks use it); ``realtime`` paces the loop to the wall clock
    (default: with ``gui``).
    """
    import pybullet

    from robocfg.geometry import pose_matrix
    from robocfg.motion.reactive import EscapeSettings, ReactiveController, ReactiveSettings
    from robocfg.motion.reactive.setup import arm_spec, body_shape, scene_shapes
    from robocfg.motion.targets import TargetMotion
    from robocfg.sim.loading import prepared_urdf
    from robocfg.sim.record import CameraView, Recorder
    from robocfg.sim.world import World

    params = params or task.config.follow_target  # type: ignore[union-attr]
    use_obstacle = params.with_obstacle if with_obstacle is None else with_obstacle
    checked = task.robots[0]
    realtime = gui if realtime is None else realtime
    t_wall = time.perf_counter()
    target = TargetMotion(params.motion, _euler_matrix(params.target_euler_deg), params.orientation,
                          math.radians(params.follow_angle_deg))
    with World(task, gui=gui) as world:
        arm = world.robot.arm()
        n_sub = max(1, round(1.0 / (params.control_rate * world.dt)))
        ctrl_dt = n_sub * world.dt
        start_tcp = arm.tcp_pose()[:3, 3]
        obstacles = _obstacles(params, use_obstacle, start_tcp, target.position(0.0))
        result = FollowTargetResult(
            task=str(task.path), robot=checked.config.name, arm=arm.config.name, motion=params.motion.type,
            orientation=params.orientation, with_obstacle=use_obstacle,
            obstacles=[o.name for o in task.config.scene.obstacles] + [o.name for o in obstacles],
            duration=params.duration, control_rate=1.0 / ctrl_dt, safety_margin=params.safety_margin,
            settle_time=params.settle_time)
        result.warnings = [p.format() for p in task.warnings] + list(world.warnings)
        if abs(1.0 / ctrl_dt - params.control_rate) > 0.01 * params.control_rate:
            result.warnings.append(f"control_rate {params.control_rate:g} Hz is not a divisor of the physics rate "
                                   f"{1.0 / world.dt:g} Hz: running at {1.0 / ctrl_dt:g} Hz ({n_sub} physics steps)")
        moving: dict[str, tuple[TargetMotion, np.ndarray]] = {}
        for ob in obstacles:
            body = Body(name=ob.name, shape=ob.shape, size=list(ob.size), mass=0.0, color=list(ob.color),
                        position=list(ob.position), quat_xyzw=list(ob.quaternion_xyzw()))
            world.add_body(body, static=True)
            if ob.motion is not None:
                T_ob = pose_matrix(ob)
                moving[ob.name] = (TargetMotion(ob.motion), T_ob)
                world.set_body_pose(ob.name, moving[ob.name][0].position(0.0), ob.quaternion_xyzw())
        env, skipped = scene_shapes(task.config.scene)
        for name in skipped:
            result.warnings.append(f"obstacle {name!r} is a mesh: the controller does not avoid it (only measured)")
        for ob in obstacles:
            shape = body_shape(ob)
            if ob.name in moving:
                shape.pose[:3, 3] = moving[ob.name][0].position(0.0)
            env.append(shape)
        spec = arm_spec(checked, prepared_urdf(checked), world.robot.base_pose(), arm.config.name,
                        params.acceleration, params.velocity_scale)
        settings = ReactiveSettings(dt=ctrl_dt, margin=params.safety_margin, gain=params.gain,
                                    max_linear_speed=params.max_speed, posture_weight=params.posture_weight,
                                    self_collision=params.self_collision, escape=EscapeSettings(enabled=params.escape))
        ctrl = ReactiveController(spec, env, settings)
        ctrl.reset(arm.joint_positions())
        result.collision_pairs = len(ctrl.pairs)
        obstacle_ids = {n: world.bodies[n] for n in result.obstacles if n in world.bodies}
        env_ids = {n: world.bodies[n] for n in ("ground", "table", "pedestal") if n in world.bodies}
        probe = _Probe(world, obstacle_ids, env_ids)
        _start_warnings(result, probe, params.safety_margin)
        marker = _marker(world, target.position(0.0))
        sliders = _sliders(world, target.position(0.0)) if gui else None
        recorder = None
        if record is not None:
            c = target.center
            view = CameraView(target=(float(c[0]) * 0.6, float(c[1]), float(c[2]) * 0.8), distance=1.5, yaw_deg=60.0, pitch_deg=-25.0)
            recorder = Recorder(world, record, fps=15.0, camera=view)
        series: list[tuple[float, float, float, float]] = []
        times: list[float] = []
        cpu: list[float] = []
        dragged = None
        try:
            steps = max(1, round(params.duration / ctrl_dt))
            for _ in range(steps):
                t = world.t
                for name, (m, T_ob) in moving.items():
                    T_ob[:3, 3] = m.position(t + ctrl_dt)
                    world.set_body_pose(name, T_ob[:3, 3], world.body_pose(name)[1])
                    ctrl.set_obstacle_pose(name, T_ob, m.velocity(t + ctrl_dt)[:3])
                try:
                    dragged = _read_sliders(world, sliders, dragged)
                    q_now = arm.joint_positions()
                except pybullet.error:  # the GUI window was closed
                    result.warnings.append(f"GUI closed at t = {world.t:.2f} s: run stopped")
                    break
                T_goal, v_goal = _goal(target, t + ctrl_dt, dragged)
                res = ctrl.step(T_goal, q_measured=q_now, velocity=v_goal)
                times.append(res.solve_time)
                cpu.append(res.cpu_time)
                if res.blocked:
                    result.blocked_time += ctrl_dt
                arm.command(res.q, res.dq)
                t_step = time.perf_counter()
                world.step(n_sub)
                T_goal, _ = _goal(target, world.t, dragged)
                world.set_body_pose(marker, T_goal[:3, 3])
                tcp = arm.tcp_pose()
                e_pos = float(np.linalg.norm(tcp[:3, 3] - T_goal[:3, 3]))
                e_rot = rotation_angle(tcp[:3, :3], T_goal[:3, :3])
                clearance = math.inf
                if obstacle_ids:
                    clearance, link, obst = probe.clearance()
                    if result.min_clearance_mm is None or clearance * 1000 < result.min_clearance_mm:
                        result.min_clearance_mm = clearance * 1000
                        result.min_clearance_link, result.min_clearance_obstacle = link, obst
                    touching = probe.contacts(obstacle_ids)
                    result.contact_steps += touching
                    result.contacts += touching and not probe.in_contact
                    probe.in_contact = touching
                if env_ids and probe.contacts(env_ids):
                    result.environment_contact_steps += 1
                series.append((world.t, e_pos, e_rot, clearance))
                if recorder is not None:
                    recorder.maybe_capture()
                if realtime:
                    time.sleep(max(0.0, ctrl_dt - (time.perf_counter() - t_step)))
        except RunFailed as exc:
            result.failed_phase, result.reason = exc.phase, exc.reason
            _summarise(result, series, times, cpu, params, ctrl)
            _finish(result, world, recorder, plot, series, t_wall)
            raise RunFailed(exc.phase, exc.reason, report=result) from None
        _summarise(result, series, times, cpu, params, ctrl)
        _finish(result, world, recorder, plot, series, t_wall)
    if not result.reached:
        tol = f"{params.reach_tolerance * 1000:.1f} mm / {math.degrees(params.orientation_tolerance):.2f} deg"
        e = result.position_error_mm
        at_rest = target.end_time <= params.duration - FINAL_WINDOW
        moving = "" if e is None or at_rest else f"RMS {e.rms:.1f} mm after settling, "
        msg = (f"target not reached within {tol}: {moving}residual {result.final_position_error_mm:.1f} mm / "
               f"{result.final_orientation_error_deg:.2f} deg ({result.unreachable_reason})")
        result.warnings.append(msg)
        if params.require_reach:
            result.failed_phase, result.reason = "track", msg
            raise RunFailed("track", msg, report=result)
    result.success = result.reached or not params.require_reach
    return result


def _goal(target, t: float, dragged: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    T = target.pose(t)
    if dragged is not None:
        T[:3, 3] = dragged
        return T, np.zeros(6)
    return T, target.velocity(t)


def _start_warnings(result: FollowTargetResult, probe: _Probe, margin: float) -> None:
    if not probe.obstacles:
        return
    for name, bid in probe.obstacles.items():
        pts = probe.p.getClosestPoints(probe.robot.body_id, bid, margin, physicsClientId=probe.world.client)
        if not pts:
            continue
        c = min(pts, key=lambda c: c[8])
        link = probe.robot.link_name(c[3])
        if c[8] < 0:
            result.warnings.append(f"obstacle {name!r} overlaps robot link {link!r} at the start by {-c[8] * 1000:.1f} mm: "
                                   "collision constraints are relaxed until the robot is clear")
        else:
            result.warnings.append(f"obstacle {name!r} is {c[8] * 1000:.1f} mm from robot link {link!r} at the start, "
                                   f"inside the safety margin ({margin * 1000:.0f} mm)")


def _summarise(result: FollowTargetResult, series, times, cpu, params: FollowTargetParams, ctrl) -> None:
    result.steps = len(times)
    result.soft_steps, result.fallback_steps, result.escapes = ctrl.soft_steps, ctrl.fallbacks, ctrl.escape.count
    if times:
        ms = np.asarray(times) * 1000
        result.step_time_median_ms = float(np.median(ms))
        result.step_time_p95_ms = float(np.percentile(ms, 95))
        ms = np.asarray(cpu) * 1000
        result.step_cpu_median_ms = float(np.median(ms))
        result.step_cpu_p95_ms = float(np.percentile(ms, 95))
    if not series:
        return
    a = np.asarray(series, float)
    t, pos, rot = a[:, 0], a[:, 1], a[:, 2]
    settled = t >= params.settle_time
    result.position_error_mm = Stats.of(pos[settled] * 1000)
    result.orientation_error_deg = Stats.of(np.degrees(rot[settled]))
    final = t >= t[-1] - FINAL_WINDOW
    result.final_position_error_mm = float(pos[final].mean() * 1000)
    result.final_orientation_error_deg = float(np.degrees(rot[final].mean()))
    every = max(1, round(1.0 / (SAMPLE_RATE * (t[1] - t[0])))) if len(t) > 1 else 1
    result.samples = [(round(float(r[0]), 4), round(float(r[1]) * 1000, 3), round(math.degrees(r[2]), 4),
                       None if math.isinf(r[3]) else round(float(r[3]) * 1000, 2)) for r in a[::every]]
    result.reached, result.unreachable_reason = _reached(result, params, ctrl)


def _reached(result: FollowTargetResult, params: FollowTargetParams, ctrl) -> tuple[bool, str | None]:
    """Reached: a target at rest at the end (static, waypoints) is within tolerance over the last
    FINAL_WINDOW; a moving one is tracked with RMS error within tolerance after settling."""
    from robocfg.motion.targets import TargetMotion

    at_rest = TargetMotion(params.motion).end_time <= params.duration - FINAL_WINDOW
    if at_rest:
        pos, rot = result.final_position_error_mm, result.final_orientation_error_deg
    elif result.position_error_mm is not None and result.orientation_error_deg is not None:
        pos, rot = result.position_error_mm.rms, result.orientation_error_deg.rms
    else:
        return False, "the run ended before the settle time"
    if pos <= params.reach_tolerance * 1000 and rot <= math.degrees(params.orientation_tolerance):
        return True, None
    if result.blocked_time > 0:
        return False, f"blocked by the environment for {result.blocked_time:.2f} s (held at the safety margin)"
    if ctrl.fallbacks:
        return False, f"the QP failed on {ctrl.fallbacks} step(s)"
    return False, "outside the workspace (or at a joint limit) for this orientation"


def _finish(result: FollowTargetResult, world, recorder, plot: Path | None, series, t_wall: float) -> None:
    result.sim_time = world.t
    if recorder is not None:
        result.record = str(recorder.save())
    if plot is not None and series:
        result.plot = str(_plot(plot, series, result.safety_margin))
    result.wall_time = time.perf_counter() - t_wall


def _plot(path: Path, series, margin: float) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    a = np.asarray(series, float)
    fig, axes = plt.subplots(2, 1, figsize=(8, 5), sharex=True)
    axes[0].plot(a[:, 0], a[:, 1] * 1000, label="position error (mm)")
    ax2 = axes[0].twinx()
    ax2.plot(a[:, 0], np.degrees(a[:, 2]), color="tab:orange", label="orientation error (deg)")
    axes[0].set_ylabel("position error (mm)")
    ax2.set_ylabel("orientation error (deg)")
    clear = np.where(np.isinf(a[:, 3]), np.nan, a[:, 3] * 1000)
    axes[1].plot(a[:, 0], clear, label="robot–obstacle clearance")
    axes[1].axhline(margin * 1000, color="tab:red", linestyle="--", label="safety margin")
    axes[1].set_ylabel("clearance (mm)")
    axes[1].set_xlabel("t (s)")
    axes[1].legend(loc="upper right")
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _marker(world, position: np.ndarray) -> int | None:
    """A green, collision-free sphere showing the target (for the GUI and recordings)."""
    import pybullet as p

    vis = p.createVisualShape(p.GEOM_SPHERE, radius=0.015, rgbaColor=[0.1, 0.8, 0.2, 0.8], physicsClientId=world.client)
    bid = p.createMultiBody(0.0, -1, vis, [float(v) for v in position], physicsClientId=world.client)
    world.bodies["_target"] = bid
    return bid


def _sliders(world, position: np.ndarray) -> list[tuple[int, float]]:
    """Debug sliders for the target position (GUI): moving one switches to the slider target."""
    import pybullet as p

    p.configureDebugVisualizer(p.COV_ENABLE_GUI, 1, physicsClientId=world.client)
    out = []
    for axis, v in zip("xyz", position, strict=True):
        sid = p.addUserDebugParameter(f"target {axis} (m)", float(v) - GUI_SLIDER_RANGE, float(v) + GUI_SLIDER_RANGE,
                                      float(v), physicsClientId=world.client)
        out.append((sid, float(v)))
    return out


def _read_sliders(world, sliders, dragged: np.ndarray | None) -> np.ndarray | None:
    if not sliders:
        return dragged
    import pybullet as p

    values = np.array([p.readUserDebugParameter(sid, physicsClientId=world.client) for sid, _ in sliders])
    if dragged is None and np.all(np.abs(values - np.array([v for _, v in sliders])) < 1e-9):
        return None
    return values
