"""Planned free-space moves for :class:`~robocfg.motion.moves.ArmMover` (pick-place ``motion: planned``).

A move to an EE pose: IK for the goal (seeded from the current joints; if that answer collides,
a few seeded restarts for a collision-free one), a collision-free joint path from the
:class:`JointPlanner`, toppra timing, then the same trajectory playback and convergence check as
every other move. A held object is attached to the hand's collision model while it is carried
(:meth:`PlannedDrive.attach`), so neither it nor the arm is planned through the scene, and the
hand keeps the orientation it carries it with along the path (:mod:`.level`: a hand turned by the
path's random samples shifts the object between the pads, which PyBullet then holds at several
points a pad, at twice the cost a step).

Build the drive once per run (:func:`build_planned_drive`): it convex-hulls every collision mesh.
Frames: world, 4×4, metres; joints in arm order, rad.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.errors import PhaseFailed
from robocfg.planning.checker import CollisionChecker
from robocfg.planning.planner import JointPlanner, PlannedPath, PlannerSettings, PlanningFailed

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.config.scene import Body
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import ArmMover
    from robocfg.sim.world import World

GOAL_IK_RESTARTS = 8  # extra IK seeds tried when the nearest IK answer for a goal collides
PARKED = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, -1000.0], [0, 0, 0, 1.0]])  # far below the scene


@dataclass
class PlannedDrive:
    """A planner for one arm in a task's scene, and what it planned (``paths``, in order)."""

    planner: JointPlanner
    kin: KinematicModel
    ee_link: str
    skipped: list[str]  # scene bodies the planner cannot see (none since meshes are convex hulls)
    base_dir: Path = Path(".")  # resolves the task's relative mesh paths (the task file's folder)
    loose: list[str] = field(default_factory=list)  # scene.objects avoided where they lie at each move
    paths: list[PlannedPath] = field(default_factory=list)
    held_at: dict[str, np.ndarray] = field(default_factory=dict)  # held objects' centres in the EE frame (m)

    @property
    def checker(self) -> CollisionChecker:
        return self.planner.checker

    def attach(self, name: str, body: Body, T_ee_body: np.ndarray) -> None:
        """Carry ``body`` at ``T_ee_body`` (4×4, its body frame in the EE link frame, m): its
        primitive, or for a mesh or URDF body the convex hull of its collision geometry."""
        from robocfg.collision.bodies import body_env_shape

        self.checker.attach(name, body_env_shape(body, T_ee_body, self.base_dir), self.ee_link)
        self.held_at[name] = np.asarray(T_ee_body, float)[:3, 3].copy()

    def detach(self, name: str) -> None:
        self.checker.detach(name)
        self.held_at.pop(name, None)

    def refresh_loose(self, world: World, ignore: Sequence[str] = ()) -> None:
        """Move the loose objects of the collision model to where they lie in ``world`` now; one
        that is held (attached) or named in ``ignore`` is parked out of the way (``PARKED``)."""
        from robocfg.geometry import pose_to_matrix

        held = {*self.checker.held, *ignore}
        for name in self.loose:
            if name in held:
                self.checker.move_shape(name, PARKED)
            elif name in world.bodies:
                pos, quat = world.body_pose(name)
                self.checker.move_shape(name, pose_to_matrix(pos, quat))

    def goal(self, mover: ArmMover, T_goal: np.ndarray, q0: np.ndarray,
             lines: Sequence[np.ndarray] = ()) -> np.ndarray:
        """A collision-free IK answer for ``T_goal`` (EE, world): the one nearest ``q0`` if it is
        free, else the free answer with the least joint travel among seeded restarts.

        ``lines``: EE poses the arm goes on to in straight lines from ``T_goal``, one after the
        other (a pick's approach and lift, a place's lowering). An answer from which IK along them
        is not continuous (a wrist or shoulder branch crossed, e.g. a joint at its limit half-way
        down: ``ArmMover.straight_waypoints``) would fail there; a free answer whose lines are
        continuous is preferred, among the same restarts. When none is, the nearest free answer
        is returned and the line fails with its own reason."""
        q = mover.solve(T_goal, q0)
        if self.checker.is_valid(q) and self.lines_continuous(mover, q, lines):
            return q
        rng = np.random.default_rng([len(q0), 0x1C])
        best, travel, fallback = None, np.inf, q if self.checker.is_valid(q) else None
        fallback_travel = 0.0 if fallback is not None else np.inf
        for _ in range(GOAL_IK_RESTARTS):
            seed = rng.uniform(self.kin.lower, self.kin.upper)
            res = self.kin.ik(T_goal, seed_q=seed, frame="ee", time_budget=mover.ik_budget, rng=rng)
            if res.converged and self.checker.is_valid(res.q):
                d = float(np.max(np.abs(res.q - q0)))
                if d < travel and self.lines_continuous(mover, res.q, lines):
                    best, travel = res.q, d
                elif d < fallback_travel:
                    fallback, fallback_travel = res.q, d
        if best is None:
            best = fallback
        if best is None:  # every answer collides: name what the nearest one hits
            hits = ", ".join(c.describe() for c in self.checker.contacts(q)[:3])
            raise PhaseFailed(mover.phase, f"the goal configuration is in collision ({hits}, "
                                           f"margin {self.checker.margin * 1000:.0f} mm)")
        return best

    @staticmethod
    def lines_continuous(mover: ArmMover, q: np.ndarray, lines: Sequence[np.ndarray]) -> bool:
        """Whether IK is continuous along the straight EE lines from FK(``q``) through ``lines``."""
        from robocfg.motion.moves import MoveFailed

        for T in lines:
            try:
                q = mover.straight_waypoints(q, T)[-1]
            except MoveFailed:
                return False
        return True

    def move(self, mover: ArmMover, T_goal: np.ndarray, check: Callable[[], str | None] | None = None,
             lines: Sequence[np.ndarray] = ()) -> None:
        """Move ``mover``'s arm to ``T_goal`` (EE, world) along a planned collision-free path, to a
        configuration from which the straight ``lines`` that follow have continuous IK if one
        is found (:meth:`goal`)."""
        self.refresh_loose(mover.world)
        q0 = mover.arm.joint_positions()
        q_goal = self.goal(mover, T_goal, q0, lines)
        try:
            path = self.planner.plan(q0, q_goal)
        except PlanningFailed as exc:
            raise PhaseFailed(mover.phase, exc.reason) from None
        if self.checker.held:  # carry the object as it was picked up (:mod:`.level`)
            path = self.levelled(mover, path)
        self.paths.append(path)
        # a held object is carried no harder than the grip holds it (the mover's max_acceleration),
        # as on every other timed move: uniformly slower along the same (checked) path
        traj = mover.slowed_for_load(self.planner.timed(path, mover.limits).trajectory)
        if mover.timeout is not None and traj.duration > mover.timeout:
            raise PhaseFailed(mover.phase, f"motion needs {traj.duration:.2f} s, more than the {mover.timeout:.2f} s timeout")
        t_start = mover.world.t
        if traj.duration > 0:
            mover.play(traj)
        mover.converge(T_goal, t_start, mover.time_limit(traj.duration))
        if check is not None:
            reason = check()
            if reason:
                raise PhaseFailed(mover.phase, reason)

    def levelled(self, mover: ArmMover, path: PlannedPath) -> PlannedPath:
        """``path`` with the hand held at its goal's orientation, turned about the held objects'
        centre (:func:`robocfg.planning.level.level_path`): still collision-free."""
        from dataclasses import replace

        from robocfg.planning.level import level_path
        from robocfg.planning.shortcut import path_length

        def solve(T: np.ndarray, seed: np.ndarray) -> np.ndarray | None:
            res = self.kin.ik(T, seed_q=seed, frame="ee", time_budget=mover.ik_budget)
            return res.q if res.converged else None

        pivot = np.mean(list(self.held_at.values()), axis=0) if self.held_at else np.zeros(3)
        W = level_path(path.waypoints, self.checker, lambda q: self.kin.fk(q, "ee"), solve,
                       self.planner.settings.resolution, pivot)
        return replace(path, waypoints=W, length=path_length(W))


def build_planned_drive(robot: CheckedRobot, world: World, kin: KinematicModel,
                        settings: PlannerSettings = PlannerSettings(), margin: float | None = None,
                        objects: Sequence[Body] = ()) -> PlannedDrive:
    """Planner for the arm of ``kin`` (a KinematicModel of ``robot``) among ``world``'s task scene:
    ground, table, pedestal, obstacles, fixture parts, and the loose ``scene.objects`` and
    ``objects`` (a command's own, e.g. pick_place_many's), avoided where they lie when each move
    starts, except while held; pick_place's object being picked is not among them."""
    from robocfg.collision import robot_geometry
    from robocfg.collision.bodies import body_env_shape
    from robocfg.motion.reactive.setup import MeshPoses, scene_shapes
    from robocfg.planning.checker import DEFAULT_MARGIN

    links, _ = robot_geometry(robot)
    scene = world.task.config.scene
    meshes = MeshPoses.of(world)  # mesh bodies' hulls where the world has them, as the controller sees them
    env, skipped = scene_shapes(scene, meshes)
    loose = []
    for obj in [*scene.objects, *objects]:  # neighbours in clutter: kept clear of like obstacles
        env.append(body_env_shape(obj, meshes.pose(obj), meshes.base_dir))
        loose.append(obj.name)
    checker = CollisionChecker(kin, links, env, DEFAULT_MARGIN if margin is None else margin)
    return PlannedDrive(JointPlanner(checker, kin.lower, kin.upper, settings), kin, kin.ee_link, skipped,
                        meshes.base_dir, loose)
