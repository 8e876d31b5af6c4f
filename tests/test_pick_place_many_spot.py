"""Bin place spots keep the open hand clear of the walls (issue 18): the hand is turned about the
object's vertical, or the object goes to a spare spot, so that the arm and the gripper with its
fingers open keep a margin from the bin's walls (``robocfg.runners.pick_place_many_spot``)."""

from __future__ import annotations

import copy

import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
from robocfg.errors import PhaseFailed
from robocfg.kinematics.frames import Grasp, ee_pose_from_grasp, grasp_rotation
from robocfg.motion.moves import ArmMover
from robocfg.runners.pick_place_many_spot import WALL_MARGIN, still_free, turned

DUCK = {"name": "duck", "shape": "mesh", "mesh": "pybullet_data://duck_vhacd.urdf", "size": [0.6, 0.6, 0.6],
        "position": [0.55, -0.10, 0.117], "euler_deg": [0, 0, 0], "mass": 0.1, "color": [0.9, 0.8, 0.1, 1.0],
        "region": {"xy_range": [0.004, 0.004], "yaw_range_deg": 10.0}}


@pytest.fixture(scope="module")
def duck_task(tmp_path_factory):
    """clear_table with red, blue and a pybullet_data duck (scale 0.6) on the table, into the bin.
    Before the hand's clearance was chosen, seed 0 episode 0 pressed the Panda's hand into the
    bin's +x wall while lowering the duck (74 contact polls, 'lower: duck: did not converge')."""
    data = copy.deepcopy(yaml.safe_load(catalog.find("tasks", "clear_table").read_text()))
    objs = data["pick_place_many"]["objects"]
    data["pick_place_many"]["objects"] = [objs[0], DUCK, objs[2]]
    path = tmp_path_factory.mktemp("duck") / "clear_table_duck.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)


def test_a_duck_goes_into_the_bin_without_the_robot_touching_the_bin(duck_task):
    lines: list[str] = []
    with open_session(duck_task, RunOptions(seed=0, log=lines.append)) as session:
        record = session.run(0)
    assert record.success, record.reason
    assert record.robot_fixture_contacts == 0, record.contacts_by_kind
    duck = next(o for o in record.objects if o.name == "duck")
    assert duck.success and duck.place_error is not None and duck.place_error < 0.02
    # the duck's spot by the +x wall needed the hand turned (or another spot): the choice acted
    assert any("to keep the open hand clear of 'bin'" in line for line in lines), lines


def _near_wall(session, inset: float) -> tuple[np.ndarray, np.ndarray]:
    """A top-down EE place pose with the fingers closing along x, the TCP 3 cm above the bin's
    floor, ``inset`` m inside the bin's +x wall on the bin's centre line; and the spot (x, y)."""
    bin_ = next(f for f in session.task.config.scene.fixtures if f.name == "bin")
    x_wall = bin_.position[0] + bin_.size[0] / 2 - bin_.wall
    xy = np.array([x_wall - inset, bin_.position[1]])
    z = bin_.position[2] + bin_.wall + 0.03
    R = grasp_rotation(np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0]))
    return ee_pose_from_grasp(Grasp(np.array([*xy, z]), R, 0.05), session.arm_cfg), xy


def test_the_hand_turns_to_clear_a_wall_and_a_spot_where_no_turn_fits_is_refused(duck_task):
    """At a spot 6 cm inside a wall the open Panda hand, closing towards the wall, reaches into it;
    turned, it clears it by the margin (pinocchio + coal on the robot's collision model). 2 cm
    inside the wall no turn fits: refused naming the bin."""
    with open_session(duck_task, RunOptions(seed=0)) as session:
        walls = session.walls
        assert walls is not None and walls.fixture == "bin"
        mover = ArmMover(session.world, session.handle, session.tools.model, session.tools.limits, phase="transport")
        q0 = np.asarray(session.arm_cfg.home, float)
        T, xy = _near_wall(session, 0.06)
        hit = walls.hits(mover, T, 0.12, q0)
        assert hit is not None and "bin/wall_+x" in hit, hit
        choice = walls.choose(mover, T, xy, [xy], 0.12, q0)
        assert choice.turn_deg != 0.0 and np.allclose(choice.xy, xy)
        assert np.allclose(choice.T_place, turned(T, xy, choice.turn_deg))
        assert walls.hits(mover, choice.T_place, 0.12, q0) is None
        q = mover.solve(choice.T_place, q0)
        assert walls.checker.clearance(q) >= WALL_MARGIN
        # a spare spot is taken when the first cannot be cleared at any turn
        T1, xy1 = _near_wall(session, 0.02)
        spare = walls.choose(mover, T1, xy1, [xy1, xy], 0.12, q0)
        assert np.allclose(spare.xy, xy)
        with pytest.raises(PhaseFailed) as exc:
            walls.choose(mover, T1, xy1, [xy1], 0.12, q0)
        assert exc.value.phase == "transport"
        assert "no place spot in 'bin' keeps the open hand 10 mm clear of its walls" in exc.value.reason


def test_a_turn_that_would_put_the_hand_on_a_placed_object_is_not_taken(duck_task):
    """The objects where they lie are in the check too (the clutter margin): with the red box
    placed where the turned hand's finger would come down (the turn the walls alone allow), that
    turn is not taken: another one that clears both is, or the spot is refused naming the objects."""
    import math

    with open_session(duck_task, RunOptions(seed=0)) as session:
        walls, world = session.walls, session.world
        mover = ArmMover(world, session.handle, session.tools.model, session.tools.limits, phase="transport")
        q0 = np.asarray(session.arm_cfg.home, float)
        T, xy = _near_wall(session, 0.06)
        first = walls.choose(mover, T, xy, [xy], 0.12, q0)  # no object spawned yet: the walls alone
        a = math.radians(first.turn_deg)
        closing = np.array([math.cos(a), math.sin(a)])  # the fingers close along world x before the turn
        red = next(b for b in session.bodies if b.name == "red")
        world.add_body(red)
        at = xy - 0.075 * closing  # a 5 cm box whose near face is 5 cm from the spot, away from the wall
        world.set_body_pose("red", np.array([*at, float(session.spots[0].z) + 0.025]))
        walls.see_objects(world, held="duck")
        hit = walls.hits(mover, first.T_place, 0.12, q0)
        assert hit is not None and "red" in hit, hit
        try:
            other = walls.choose(mover, T, xy, [xy], 0.12, q0)
        except PhaseFailed as exc:
            assert "mm clear of the objects" in exc.reason
        else:
            assert other.turn_deg != first.turn_deg and walls.hits(mover, other.T_place, 0.12, q0) is None


def test_off_grid_spots_keep_the_gap_from_placed_objects_and_come_nearest_first():
    """The lattice's points clear of the placed objects' footprints (plus the gap), the tried
    spots left out, nearest the assigned spot first; a grid spot an off-grid footprint comes
    within the gap of is reported overlapped."""
    from robocfg.checks.clutter import off_grid_spots, overlapped

    lattice = np.array([[x, y, 0.1] for x in (0.0, 0.02, 0.04, 0.06) for y in (0.0, 0.02)])
    placed = [(np.array([0.06, 0.0]), 0.01)]
    got = off_grid_spots(lattice, np.array([0.0, 0.0]), 0.01, 0.005, placed, [np.array([0.0, 0.0])])
    assert [tuple(np.round(p, 3)) for p in got] == [(0.0, 0.02), (0.02, 0.0), (0.02, 0.02), (0.04, 0.02)]
    assert all(np.linalg.norm(p - placed[0][0]) >= 0.025 for p in got)
    spots = np.array([[0.0, 0.0], [0.03, 0.0], [0.05, 0.0]])
    assert overlapped(np.array([0.0, 0.0]), 0.01, spots, 0.01, 0.01).tolist() == [True, False, False]
    assert overlapped(np.array([0.02, 0.0]), 0.01, spots, 0.01, 0.01).tolist() == [True, True, False]
    # the spot taken goes, and every one the footprint comes within the gap of; on the grid only the one taken
    assert still_free(spots, [0, 1, 2], np.array([0.02, 0.0]), 0.01, 0.01, 0.01) == [2]
    assert still_free(spots, [0, 1, 2], np.array([0.0, 0.0]), 0.01, 0.01, 0.01) == [1, 2]


@pytest.fixture(scope="module")
def tight_bin_task(tmp_path_factory):
    """The duck alone into a bin 0.201 × 0.26 m (gap 5 mm): its 2 × 2 grid's spots are 4.7 cm from
    the ±x walls and 7.6 cm from the ±y walls, where the open Panda hand fits at no turn; the
    bin's middle, off the grid, has room."""
    data = copy.deepcopy(yaml.safe_load(catalog.find("tasks", "clear_table").read_text()))
    data["scene"]["fixtures"][0]["size"] = [0.201, 0.26, 0.06]
    data["pick_place_many"]["objects"] = [DUCK]
    data["pick_place_many"]["place"]["gap"] = 0.005
    path = tmp_path_factory.mktemp("tight") / "duck_tight_bin.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return load_task(path)


def test_every_grid_spot_refused_the_duck_is_placed_off_the_grid(tight_bin_task):
    """Seed 0 episode 0: no grid spot clears the open hand at any turn, so an off-grid spot on
    the duck's lattice is tried and taken; the duck rests there (its pose read from the world)
    and the robot touches no fixture."""
    lines: list[str] = []
    with open_session(tight_bin_task, RunOptions(seed=0, log=lines.append)) as session:
        grid, lattice = session.spot_xy.copy(), session.lattice[0].copy()
        record = session.run(0)
        final = session.world.body_pose("duck")[0]
    assert len(grid) == 4
    assert record.success, record.reason
    assert record.robot_fixture_contacts == 0, record.contacts_by_kind
    duck = record.objects[0]
    target = np.array(duck.place_target)
    assert np.min(np.linalg.norm(grid - target, axis=1)) > 0.01  # off the grid
    assert np.min(np.linalg.norm(lattice - target, axis=1)) < 1e-5  # on the lattice
    assert np.linalg.norm(final[:2] - target) < 0.01 and np.allclose(duck.final, final, atol=1e-6)
    assert any("off the grid" in line for line in lines), lines


def test_no_spot_anywhere_is_refused_naming_the_off_grid_spots_tried(tight_bin_task):
    """With the hand 2 cm inside the bin's wall at its only grid spot and every off-grid spot
    as tight (the same point), the refusal names how many off-grid spots were tried."""
    with open_session(tight_bin_task, RunOptions(seed=0)) as session:
        walls = session.walls
        assert walls is not None
        mover = ArmMover(session.world, session.handle, session.tools.model, session.tools.limits, phase="transport")
        q0 = np.asarray(session.arm_cfg.home, float)
        T, xy = _near_wall(session, 0.02)
        with pytest.raises(PhaseFailed) as exc:
            walls.choose(mover, T, xy, [xy], 0.12, q0, lambda: [xy.copy(), xy.copy()])
        assert "; 2 off-grid spots tried too)" in exc.value.reason
        choice = walls.choose(mover, T, xy, [xy], 0.12, q0, lambda: [xy.copy(), np.array([0.5, 0.27])])
        assert np.allclose(choice.xy, [0.5, 0.27]) and walls.hits(mover, choice.T_place, 0.12, q0) is None
