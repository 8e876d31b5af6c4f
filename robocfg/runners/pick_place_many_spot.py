"""Where, and turned how far, an object is put into a bin so that the open hand clears the walls.

The place spots (:func:`robocfg.checks.clutter.place_spots`) keep the *object's* footprint
``gap`` from a bin's walls; the hand around it is wider (a Panda hand is 0.2 m across its closing
axis, the open fingers 0.1 m) and, for an object grasped low, comes down below the walls' tops: a
duck placed 9 cm from a wall pressed the Panda's hand into it while lowering. So before the
transport the hand's turn about the vertical through the object's centre (the object turns with
it) is chosen such that the arm and the gripper, fingers open (the release width: the kinematic
model holds the gripper open), keep ``WALL_MARGIN`` from the bin's walls, and the clutter margin
from the objects where they lie (those already placed), at the place pose and all along the
straight line up to the highest pose the lower starts from or the retract ends at — tested with
pinocchio + coal on the robot's own collision geometry (two
:class:`~robocfg.planning.checker.CollisionChecker`: the walls; the objects, the held one parked). The turn nearest
zero is taken (turning by 0 changes nothing); a spot where no turn fits gives way to the next free
spot; when no grid spot fits, up to ``MAX_OFF_GRID`` spots off the grid (a finer lattice in the
same bin, clear of the placed objects, nearest the assigned spot first:
:func:`robocfg.checks.clutter.off_grid_spots`) are tried the same way; when none fits anywhere the
phase fails naming what the hand would touch and how many off-grid spots were tried.

Frames: world, 4×4, metres; turns in degrees about the world's z axis.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.motion.moves import MoveFailed

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.config.scene import Body, Scene
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import ArmMover
    from robocfg.planning.checker import CollisionChecker
    from robocfg.sim.world import World

CHECK_STEP = 0.03  # m between the configurations checked along the line up (on the path played)
WALL_MARGIN = 0.01  # m the open hand and the arm keep from a bin's walls (the planner's margin)
# turns (deg) tried, nearest first; a parallel gripper turned by 180° is the same hand
TURNS_DEG = (0.0, 15.0, -15.0, 30.0, -30.0, 45.0, -45.0, 60.0, -60.0, 75.0, -75.0, 90.0)
# off-grid spots tried at most after the grid's (each: up to len(TURNS_DEG) IK solves + line checks)
MAX_OFF_GRID = 16


def turned(T: np.ndarray, centre_xy: np.ndarray, deg: float) -> np.ndarray:
    """``T`` (4×4, world) turned by ``deg`` about the vertical through ``centre_xy`` (m)."""
    a = math.radians(deg)
    Rz = np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])
    out = T.copy()
    out[:3, :3] = Rz @ T[:3, :3]
    c = np.array([centre_xy[0], centre_xy[1], 0.0])
    out[:3, 3] = c + Rz @ (T[:3, 3] - c)
    out[2, 3] = T[2, 3]
    return out


def still_free(spot_xy: np.ndarray, free: list[int], xy: np.ndarray, radius: float, spot_radius: float,
               gap: float) -> list[int]:
    """``free`` (indices of the grid's spots ``spot_xy``, k × 2, m) without the one nearest ``xy``
    (x, y, m: where an object of footprint ``radius`` went) and every one its footprint there
    comes within ``gap`` of, an object of footprint ``spot_radius`` on it: an off-grid spot can
    cover grid spots, which are then no later object's to take. On the grid (``radius`` ≤
    ``spot_radius``) only the spot taken goes."""
    from robocfg.checks.clutter import overlapped

    if not free:
        return free
    nearest = min(free, key=lambda j: float(np.linalg.norm(spot_xy[j] - xy)))
    hit = overlapped(xy, radius, spot_xy[free], spot_radius, gap)
    return [j for j, h in zip(free, hit, strict=True) if j != nearest and not h]


@dataclass(frozen=True)
class PlaceChoice:
    """A spot's centre (x, y, m), the turn (deg) and the EE place pose (4×4, world) taken."""

    xy: np.ndarray
    turn_deg: float
    T_place: np.ndarray


class BinWalls:
    """The walls of the bin the objects go into, and the objects, as collision models of the arm
    with the gripper open among them (see the module doc)."""

    def __init__(self, checker: CollisionChecker, fixture: str, objects: CollisionChecker | None = None):
        self.checker, self.fixture, self.objects = checker, fixture, objects

    @classmethod
    def build(cls, robot: CheckedRobot, kin: KinematicModel, scene: Scene, fixture: str,
              objects: Sequence[Body] = (), base_dir: Path = Path("."), object_margin: float = 0.0) -> BinWalls:
        """Walls (every part but the floor) of bin ``fixture`` of ``scene`` around the arm of
        ``kin``; ``objects`` (parked until :meth:`see_objects` puts them where they lie) kept
        ``object_margin`` (m) from; ``base_dir`` resolves their mesh paths."""
        from robocfg.collision import robot_geometry
        from robocfg.collision.bodies import body_env_shape
        from robocfg.motion.reactive.setup import scene_shapes
        from robocfg.planning.checker import CollisionChecker
        from robocfg.planning.drive import PARKED

        links, _ = robot_geometry(robot)
        env, _ = scene_shapes(scene)
        walls = [e for e in env if e.name.startswith(f"{fixture}/") and e.name != f"{fixture}/floor"]
        shapes = [body_env_shape(b, PARKED, base_dir) for b in objects]
        neighbours = CollisionChecker(kin, links, shapes, object_margin) if shapes else None
        return cls(CollisionChecker(kin, links, walls, WALL_MARGIN), fixture, neighbours)

    def see_objects(self, world: World, held: str) -> None:
        """Put the objects where they lie in ``world``; ``held`` (and any not spawned) parked."""
        from robocfg.geometry import pose_to_matrix
        from robocfg.planning.drive import PARKED

        if self.objects is None:
            return
        for name in self.objects.env:
            T = pose_to_matrix(*world.body_pose(name)) if name != held and name in world.bodies else PARKED
            self.objects.move_shape(name, T)

    def hits(self, mover: ArmMover, T_place: np.ndarray, top: float, q0: np.ndarray) -> str | None:
        """What the arm touches (within the margin) at ``T_place`` or on the straight line up to
        height ``top`` (m) above it; None when it is clear. IK seeded from ``q0``; an unreachable
        line counts as a hit (named)."""
        T_top = T_place.copy()
        T_top[2, 3] += top
        try:
            q = mover.solve(T_place, q0)
            _, path = mover.straight_path(q, T_top)
        except MoveFailed as exc:
            return exc.reason
        # the played path at evenly spaced parameters: about every CHECK_STEP of the line
        line = path(np.linspace(0.0, 1.0, max(2, math.ceil(top / CHECK_STEP) + 1)))
        for qi in line:
            for checker in (self.checker, self.objects):
                if checker is not None and not checker.is_valid(qi):
                    hit = checker.contacts(qi)
                    return hit[0].describe() if hit else "a pair within the margin"
        return None

    def choose(self, mover: ArmMover, T_place: np.ndarray, obj_xy: np.ndarray, spots: list[np.ndarray],
               top: float, q0: np.ndarray, off_grid: Callable[[], list[np.ndarray]] | None = None) -> PlaceChoice:
        """The first of ``spots`` (x, y, m; in order) with the least turn that clears the walls;
        failing all, the first of at most ``MAX_OFF_GRID`` of ``off_grid()`` (asked only then).
        ``T_place``: the EE place pose with the object's centre at ``obj_xy``, untuned."""
        misses: list[str] = []
        choice = self._first_clear(mover, T_place, obj_xy, spots, top, q0, misses)
        extra = list(off_grid()[:MAX_OFF_GRID]) if choice is None and off_grid is not None else []
        if choice is None and extra:
            choice = self._first_clear(mover, T_place, obj_xy, extra, top, q0, [])
        if choice is not None:
            return choice
        objects = "" if self.objects is None else f" and {self.objects.margin * 1000:.0f} mm clear of the objects"
        tried = "" if off_grid is None else f"; {len(extra)} off-grid spots tried too"
        raise MoveFailed(mover.phase, f"no place spot in {self.fixture!r} keeps the open hand "
                                      f"{WALL_MARGIN * 1000:.0f} mm clear of its walls{objects} at any turn "
                                      f"(unturned: {'; '.join(misses)}{tried})")

    def _first_clear(self, mover: ArmMover, T_place: np.ndarray, obj_xy: np.ndarray, spots: Sequence[np.ndarray],
                     top: float, q0: np.ndarray, misses: list[str]) -> PlaceChoice | None:
        """The first of ``spots`` with the least turn that clears (None: none); what each spot
        touches unturned is added to ``misses``."""
        for xy in spots:
            shift = np.array([xy[0] - obj_xy[0], xy[1] - obj_xy[1], 0.0])
            T_at = T_place.copy()
            T_at[:3, 3] += shift
            for deg in TURNS_DEG:
                T = turned(T_at, np.asarray(xy, float), deg)
                why = self.hits(mover, T, top, q0)
                if why is None:
                    return PlaceChoice(np.asarray(xy, float), deg, T)
                if deg == 0.0:
                    misses.append(f"[{xy[0]:.3f}, {xy[1]:.3f}]: {why}")
        return None
