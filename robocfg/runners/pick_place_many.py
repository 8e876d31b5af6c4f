"""``run pick-place-many``: several objects picked in turn (out of clutter or a bin) and placed into
a bin or onto a shelf level, over seeded episodes.

Episode k draws every object's position and yaw within its own region from
``default_rng([seed, k])`` (in the order listed), spawns them all, lets them settle, then picks
them one at a time in the listed order or, with ``order: reachability``, at each turn the object
whose collision-free grasp needs the least joint travel. The i-th object placed goes to the i-th
place spot (:func:`robocfg.checks.clutter.place_spots`: spaced so placed objects do not land on
each other; a bin spot where the open hand fits at no turn gives way to the next free one, and
when none does, to a spot off the grid: :mod:`.pick_place_many_spot`). Each object runs pick-place's phases (:mod:`.pick_place_many_machine`); the first
failure ends the episode and names the object and the phase. Before simulating: the scene checks
of :mod:`robocfg.checks.clutter` (at load) and, here, IK reach of every object's spot (nominal and
region corners) and of every place spot used.

Over 300 lines: the session (its episode loop with the place-spot bookkeeping, the replay judge)
and the static reach check share the spot helpers at the top; the spot geometry itself lives in
:mod:`robocfg.checks.clutter` and :mod:`.pick_place_many_spot`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robocfg.config.commands import Limits, PickPlaceParams, PickPlaceRandomize, Region
from robocfg.config.multi_pick import PickObject, PickPlaceManyParams
from robocfg.config.robot import ParallelGripperConfig
from robocfg.config.scene import Body
from robocfg.engine.dataset import ReplayScene
from robocfg.engine.options import FrameRecorder
from robocfg.engine.randomize import place_randomly
from robocfg.engine.registry import register_task
from robocfg.engine.session import EpisodeSession, EpisodicRunner
from robocfg.errors import ConfigError, Problem
from robocfg.motion.moves import MoveFailed, bound_ik_by_iterations
from robocfg.runners.pick_place_many_command import PickPlaceManyCommand
from robocfg.runners.pick_place_many_machine import ClutterFilter, ContactWatch, ObjectMachine, Spot
from robocfg.runners.pick_place_many_report import ManyEpisode, ManyReport, ObjectRecord, summarise
from robocfg.runners.pick_place_many_spot import BinWalls, still_free
from robocfg.runners.pick_place_setup import EpisodeSetup, _Tools

BLOCK = "pick_place_many"


def as_body(o: PickObject) -> Body:
    """The object without its region."""
    return Body(**{k: getattr(o, k) for k in Body.model_fields})


def object_params(params: PickPlaceManyParams, body: Body, place_xy: np.ndarray) -> PickPlaceParams:
    """Pick-place's parameters for one object going to ``place_xy`` (the shared settings)."""
    return PickPlaceParams(
        object=body, place_position=[float(place_xy[0]), float(place_xy[1]), 0.0],
        randomize=PickPlaceRandomize(object=Region(), place=Region()), above_height=params.above_height,
        lift_height=params.lift_height, grasp_depth=params.grasp_depth, position_tolerance=params.position_tolerance,
        orientation_tolerance=params.orientation_tolerance, timeouts=params.timeouts, motion=params.motion,
        speed_scale=params.speed_scale, grip_force=params.grip_force, success_tolerance=params.success_tolerance,
        max_tilt_deg=params.max_tilt_deg)


def spots_for(task, params: PickPlaceManyParams, spare: bool = False) -> list[Spot]:
    """The place spots the objects take, in order (one per object; ``spare``: every spot the
    target holds, the first ones those)."""
    from robocfg.checks.clutter import footprint_radius, place_fixture, place_spots
    from robocfg.config.fixtures import ShelfFixture

    scene = task.config.scene
    radius = max(footprint_radius(o, task.path.parent) for o in params.objects)
    spots = place_spots(scene, params.place, radius)
    f = place_fixture(scene, params.place)
    to_front = params.place.depth * (f.size[0] - f.board) if isinstance(f, ShelfFixture) else 0.0
    points = spots.points if spare else spots.points[: len(params.objects)]
    return [Spot(float(p[2]), spots.front, to_front, spots.ceiling) for p in points]


def spot_points(task, params: PickPlaceManyParams, spare: bool = False) -> np.ndarray:
    """Centres (k, 3; m, world) of the spots of :func:`spots_for`."""
    from robocfg.checks.clutter import footprint_radius, place_spots

    radius = max(footprint_radius(o, task.path.parent) for o in params.objects)
    points = place_spots(task.config.scene, params.place, radius).points
    return points if spare else points[: len(params.objects)]


class ManySession(EpisodeSession[ManyEpisode]):
    """The world, kinematic model, planner, grasp filter and place spots every episode shares.

    Each episode after the first gets a newly built world (``fresh_world_per_episode``): objects
    standing close together (clear_table) ended micrometres apart after a restore, Bullet's pair
    order following the objects removed before (``deterministicOverlappingPairs`` fixes that but
    moves every result and jammed a shelf release, seed 0)."""

    fresh_world_per_episode = True
    phases = ("setup", "pre_grasp", "approach", "grasp", "lift", "transport", "lower", "release", "retract", "withdraw")

    def prepare(self) -> None:
        from robocfg.assets.object_shape import object_shape
        from robocfg.checks.grip_force import pad_force
        from robocfg.grasp.gripper_model import measure_gripper
        from robocfg.kinematics.model import KinematicModel
        from robocfg.motion.limits import limits_from_robot
        from robocfg.planning.drive import build_planned_drive

        robot = self.task.robots[0]
        self.arm_cfg = robot.config.arm(self.options.arm)
        self.params: PickPlaceManyParams = self.task.config.pick_place_many  # type: ignore[union-attr]
        self.handle = self.world.robot.arm(self.arm_cfg.name)
        self.bodies = [as_body(o) for o in self.params.objects]
        self.bodies_index = {b.name: i for i, b in enumerate(self.bodies)}
        self.shapes = [object_shape(b, self.task.path.parent) for b in self.bodies]
        # every spot of the target: the first ones in order, the rest spare (a spot where the open
        # hand cannot clear a bin's walls gives way to the next free one)
        self.spots = spots_for(self.task, self.params, spare=True)
        self.spot_xy = spot_points(self.task, self.params, spare=True)[:, :2]
        from robocfg.checks.clutter import bin_lattice, footprint_radius

        self.radii = [footprint_radius(o, self.task.path.parent) for o in self.params.objects]
        self.lattice = [bin_lattice(self.task.config.scene, self.params.place, r)[:, :2] for r in self.radii]
        model = KinematicModel.from_robot(robot, arm=self.arm_cfg.name, base_pose=self.world.robot.base_pose())
        bound_ik_by_iterations(model)
        scale = self.params.speed_scale
        limits = limits_from_robot(robot, self.handle.joints, Limits(velocity_scale=scale, acceleration_scale=scale))
        boxes = measure_gripper(self.world.robot, self.handle) if isinstance(self.arm_cfg.gripper, ParallelGripperConfig) else None
        planned = None
        if self.params.motion == "planned":
            planned = build_planned_drive(robot, self.world, model, objects=self.bodies)
        self.tools = _Tools(model, limits, None, planned, boxes=boxes, pad_force=pad_force(robot, self.arm_cfg))
        self.clutter = build_planned_drive(robot, self.world, model, margin=self.params.clutter_margin, objects=self.bodies)
        self.walls = self._bin_walls(model)
        scene = self.task.config.scene
        self.parts = [b.name for b in [*scene.obstacles, *scene.fixture_parts()]]

    def _bin_walls(self, model) -> BinWalls | None:
        """The target bin's walls around the arm (None for a shelf)."""
        from robocfg.checks.clutter import place_fixture
        from robocfg.config.fixtures import BinFixture

        scene = self.task.config.scene
        if not isinstance(place_fixture(scene, self.params.place), BinFixture):
            return None
        return BinWalls.build(self.task.robots[0], model, scene, self.params.place.fixture, self.bodies,
                              self.task.path.parent, self.params.clutter_margin)

    def _machines(self, k: int, recorder: FrameRecorder | None,
                  on_step: Callable[[], None] | None) -> dict[str, ObjectMachine]:
        """Episode ``k``'s objects spawned (each in its region, drawn from ``rng(k)``) and their
        machines, by name in the task's order."""
        rng = self.rng(k)
        placed = [place_randomly(b, o.region, rng) for b, o in zip(self.bodies, self.params.objects, strict=True)]
        ids = [self.world.add_body(pl.body) for pl in placed]
        for pl in reversed(placed):  # removed last-spawned first (Bullet's arrays shrink from the end)
            self.remove_after_episode(pl.body.name)
        clutter = ClutterFilter(self.clutter)
        machines: dict[str, ObjectMachine] = {}
        for i, (pl, bid) in enumerate(zip(placed, ids, strict=True)):
            body = pl.body
            yaw = math.radians((self.bodies[i].euler_deg or [0, 0, 0])[2]) + pl.yaw
            setup = EpisodeSetup(k, self.seed + k, body, yaw, self.spot_xy[0])
            tools = dataclasses.replace(self.tools, shape=self.shapes[i])
            machines[body.name] = ObjectMachine(
                self.world, self.handle, tools, object_params(self.params, body, self.spot_xy[0]), setup, recorder,
                self.log_for(k), body_id=bid, clutter=clutter, spot=self.spots[0], on_step=on_step,
                place_clearance=self.params.place_clearance, walls=self.walls)
        return machines

    def _instruction(self) -> str:
        from robocfg.checks.clutter import place_fixture
        from robocfg.config.fixtures import ShelfFixture
        from robocfg.datasets.language import pick_place_many_instruction

        shelf = isinstance(place_fixture(self.task.config.scene, self.params.place), ShelfFixture)
        return pick_place_many_instruction(self.params, shelf)

    def episode(self, k: int, recorder: FrameRecorder | None) -> ManyEpisode:
        current: list[ObjectMachine] = []
        watch = ContactWatch(self.world, self.parts, lambda: current[0].mover.phase if current else "setup")
        machines = self._machines(k, recorder, watch.on_step)
        self.record_from(self.handle, {n: m.obj for n, m in machines.items()},
                         lambda: current[0].mover.phase if current else "setup", self._instruction)
        first = next(iter(machines.values()))
        first.gripper.open()
        first.mover.settle(0.2)
        starts = {n: m.world.body_pose(m.obj) for n, m in machines.items()}
        remaining, order = list(machines), list[str]()
        free = list(range(len(self.spot_xy)))  # spots not taken yet, in order
        failure: tuple[str, str, str] | None = None
        while remaining and failure is None:
            for n in remaining:
                machines[n].assign(self.spot_xy[free[0]], self.spots[free[0]])
            name = self._next(machines, remaining)
            m = machines[name]
            m.spare_xy = [self.spot_xy[i] for i in free[1:]]
            m.off_grid = self._off_grid(machines, name, order, free, len(remaining) - 1)
            current[:] = [m]
            order.append(name)
            remaining.remove(name)
            try:
                m.run()
            except MoveFailed as exc:
                m.close_phase(False, exc.reason)
                failure = (name, exc.phase, exc.reason)
            free = self._still_free(free, self.bodies_index[name], m.setup.place_xy)
        records = [self._record(machines[b.name], b.name in order, starts[b.name], failure) for b in self.bodies]
        return ManyEpisode(
            index=k, seed=self.seed + k, success=failure is None, failed_phase=failure[1] if failure else None,
            failed_object=failure[0] if failure else None,
            reason=f"{failure[0]}: {failure[2]}" if failure else f"{len(order)} objects placed",
            placed=sum(r.success for r in records), order=order, robot_fixture_contacts=watch.count,
            first_contact=watch.first, sim_time=round(self.world.t, 6), steps=self.world.steps, objects=records,
            contacts_by_kind=dict(sorted(watch.by_kind.items())),
            closest_fixture=None if watch.closest is None else round(watch.closest, 6))

    def scene(self, k: int) -> ReplayScene:
        machines = self._machines(k, None, None)

        def judge() -> tuple[bool, str]:
            """Every object at rest on its own place spot (the nearest unused grid spot, in the
            task's order, or, farther than the tolerance from every free one, the nearest point of
            its off-grid lattice: which off-grid spot the run took is not known here), upright:
            the run's final check of each object."""
            free = list(range(len(self.spot_xy)))
            for name, m in machines.items():
                xy = self.world.body_pose(m.obj)[0][:2]
                j = min(free, key=lambda i: float(np.linalg.norm(self.spot_xy[i] - xy)), default=None)
                at = self.spot_xy[j] if j is not None else None
                lattice = self.lattice[self.bodies_index[name]]
                if (at is None or np.linalg.norm(at - xy) > self.params.success_tolerance) and len(lattice):
                    at = lattice[int(np.argmin(np.linalg.norm(lattice - xy, axis=1)))]  # an off-grid spot
                if at is None:
                    return False, f"{name}: place: no place spot left for it"
                free = self._still_free(free, self.bodies_index[name], at)
                m.assign(at, self.spots[0 if j is None else j])
                try:
                    m._check_placed()
                except MoveFailed as exc:
                    return False, f"{name}: {exc.phase}: {exc.reason}"
            return True, f"{len(machines)} objects placed"

        return ReplayScene(self.world, self.handle, {n: m.obj for n, m in machines.items()}, judge)

    def _still_free(self, free: list[int], i: int, xy: np.ndarray) -> list[int]:
        """``free`` once object ``i`` went to ``xy`` (:func:`.pick_place_many_spot.still_free`)."""
        return still_free(self.spot_xy, free, xy, self.radii[i], max(self.radii), self.params.place.gap)

    def _off_grid(self, machines: dict[str, ObjectMachine], name: str, order: list[str], free: list[int],
                  later: int) -> Callable[[], list[np.ndarray]] | None:
        """The off-grid spots (x, y, m; nearest the assigned spot first) object ``name`` may take
        when no grid spot clears the hand: on its lattice, its footprint ``gap`` from the objects
        placed so far (``order``, where they lie now), and leaving ``later`` grid spots of ``free``
        for the objects after it. None for a shelf."""
        from robocfg.checks.clutter import off_grid_spots

        i = self.bodies_index[name]
        if self.walls is None or not len(self.lattice[i]):
            return None
        m = machines[name]

        def spots() -> list[np.ndarray]:
            placed = [(self.world.body_pose(machines[n].obj)[0][:2], self.radii[self.bodies_index[n]]) for n in order
                      if n != name]
            tried = [self.spot_xy[j] for j in free]
            cands = off_grid_spots(self.lattice[i], m.setup.place_xy, self.radii[i], self.params.place.gap, placed, tried)
            return [c for c in cands if len(self._still_free(free, i, c)) >= later]

        return spots

    def _next(self, machines: dict[str, ObjectMachine], remaining: list[str]) -> str:
        """The next object: the first listed, or (reachability) the one whose collision-free grasp
        needs the least joint travel (the first listed when none has one: it fails naming why)."""
        if self.params.order == "listed":
            return remaining[0]
        costs = []
        for n in remaining:
            try:
                costs.append(machines[n].plan_grasp())
            except MoveFailed:
                costs.append(math.inf)
        best = int(np.argmin(costs))
        return remaining[best] if costs[best] < math.inf else remaining[0]

    def _record(self, m: ObjectMachine, attempted: bool, start, failure: tuple[str, str, str] | None) -> ObjectRecord:
        pos, quat = self.world.body_pose(m.obj)
        from robocfg.geometry import quat_to_matrix

        mine = failure is not None and failure[0] == m.setup.body.name
        ok = attempted and not mine
        tilt = m.shape.tilt_deg(quat_to_matrix(start[1]), quat_to_matrix(quat))
        return ObjectRecord(
            name=m.setup.body.name, attempted=attempted, success=ok, failed_phase=failure[1] if mine and failure else None,
            reason=(failure[2] if mine and failure else "placed" if ok else "not attempted: an earlier object failed"),
            start=[round(float(v), 6) for v in start[0]], start_yaw_deg=round(math.degrees(m.setup.yaw), 4),
            place_target=[round(float(v), 6) for v in m.setup.place_xy] if attempted else [],
            final=[round(float(v), 6) for v in pos],
            place_error=round(float(np.linalg.norm(pos[:2] - m.setup.place_xy)), 6) if attempted else None,
            tilt_deg=round(tilt, 4), grasp_candidates=m.candidates, grasps_in_collision=m.in_collision,
            phases=m.phases)

    def report(self, records: list[ManyEpisode], interrupted: bool) -> ManyReport:
        warnings = [w.format() for w in self.task.warnings]
        planned = self.tools.planned
        unseen = planned.skipped if planned is not None else []
        warnings += [f"body {name!r} is a mesh: the planner does not avoid it" for name in unseen]
        warnings += list(self.reach_warnings)
        return ManyReport(task=str(self.task.path), robot=self.task.robots[0].config.name, arm=self.arm_cfg.name,
                          seed=self.seed, summary=summarise(records), episodes=records, warnings=warnings,
                          interrupted=interrupted)

    reach_warnings: tuple[str, ...] = ()


@register_task
class PickPlaceManyRunner(PickPlaceManyCommand, EpisodicRunner):
    params = PickPlaceManyParams
    report = ManyReport

    def check(self) -> None:
        super().check()
        self._reach = self.static_problems(self.task, self.options.arm)
        errors = [p for p in self._reach if p.severity == "error"]
        if errors:
            raise ConfigError(errors)

    def open_session(self) -> ManySession:
        session = ManySession(self.task, self.options)
        session.reach_warnings = tuple(p.format() for p in getattr(self, "_reach", []) if p.severity == "warning")
        return session


@dataclass(frozen=True)
class _Point:
    what: str
    phase: str
    point: np.ndarray
    nominal: bool
    loc: tuple


def reach_many(task, arm: str | None = None) -> list[Problem]:
    """IK reach, tool pointing down, of every object's grasp and pre-grasp points (nominal: error;
    region corners: warning) and of every place spot used with the point above it (error)."""
    from itertools import product

    from robocfg.assets.object_shape import object_shape
    from robocfg.geometry import pose_matrix, quat_to_matrix
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.reach import _best_residual, support_height

    params: PickPlaceManyParams = task.config.pick_place_many
    robot = task.robots[0]
    arm_cfg = robot.config.arm(arm)
    model = KinematicModel.from_robot(robot, arm=arm_cfg.name, base_pose=pose_matrix(task.config.robots[0]))
    bound_ik_by_iterations(model)
    home = np.asarray(arm_cfg.home, float)
    scene, base = task.config.scene, task.path.parent
    spots = spot_points(task, params)
    rise = params.place_clearance if spots_for(task, params)[0].ceiling is not None else params.lift_height
    points: list[_Point] = []
    for k, o in enumerate(params.objects):
        shape = object_shape(o, base)
        up = shape.below_origin(quat_to_matrix(o.quaternion_xyzw()))
        loc = (BLOCK, "objects", k, "position")
        rx, ry = o.region.xy_range
        corners = [(True, (0.0, 0.0)), *((False, c) for c in product((-1.0, 1.0), repeat=2) if rx or ry)]
        for nominal, (sx, sy) in corners:
            x, y = o.position[0] + sx * rx, o.position[1] + sy * ry
            z = support_height(scene, x, y, base) + up
            points.append(_Point(f"object {o.name!r}: the pose above it", "pre_grasp",
                                 np.array([x, y, z + params.above_height]), nominal, loc))
            points.append(_Point(f"object {o.name!r}: its grasp pose", "approach", np.array([x, y, z]), nominal, loc))
        sp = spots[k]
        z = float(sp[2]) + up
        ploc = (BLOCK, "place", "fixture")
        points.append(_Point(f"place spot {k + 1} ([{sp[0]:.3f}, {sp[1]:.3f}] m)", "lower", np.array([sp[0], sp[1], z]), True, ploc))
        points.append(_Point(f"the pose above place spot {k + 1}", "transport", np.array([sp[0], sp[1], z + rise]), True, ploc))
    out: list[Problem] = []
    for pt in points:
        residual = _best_residual(model, arm_cfg, home, pt.point)
        if residual is None:
            continue
        x, y, z = pt.point
        where = "nominal point" if pt.nominal else "a corner of its randomisation region"
        out.append(task.doc.problem(pt.loc, f"{pt.phase}: {pt.what} is out of the arm's reach ({where}, TCP at "
                                            f"[{x:.3f}, {y:.3f}, {z:.3f}] m, IK residual {residual * 1000:.0f} mm)",
                                    "error" if pt.nominal else "warning"))
    return out
