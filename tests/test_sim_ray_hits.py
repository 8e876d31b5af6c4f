"""Rays through several bodies: a mesh object resting on a thin slab does not hide the slab."""

import pybullet as p
import pybullet_data
import pytest

from robocfg.sim.queries import SceneQueries


class _Queries(SceneQueries):
    def __init__(self, client: int) -> None:
        self.client = client


@pytest.fixture()
def client():
    c = p.connect(p.DIRECT)
    yield c
    p.disconnect(c)


def test_a_ray_finds_the_thin_slab_under_a_resting_duck(client) -> None:
    p.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=client)
    top = 0.70
    slab = p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.2, 0.2, 0.025],
                                                       physicsClientId=client),
                             basePosition=[0, 0, top - 0.025], physicsClientId=client)
    duck = p.loadURDF("duck_vhacd.urdf", [0, 0, top + 0.05], physicsClientId=client)
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    for _ in range(480):
        p.stepSimulation(physicsClientId=client)
    lo, _ = p.getAABB(duck, -1, physicsClientId=client)
    x, y = p.getBasePositionAndOrientation(duck, physicsClientId=client)[0][:2]
    hits = _Queries(client).ray_hits([x, y, 5.0], [x, y, -1.0])
    bodies = [h.body for h in hits]
    assert bodies[:2] == [duck, slab], (bodies, lo)
    assert hits[1].position[2] == pytest.approx(top, abs=1e-3)
    # The duck's bounding box (with Bullet's margin) reaches into the slab: restarting the ray past
    # it, as this query once did, started inside the slab and missed it.
    assert lo[2] < top


def test_the_first_hit_not_skipped_is_that_of_all_hits_and_stops_the_casts(client, monkeypatch) -> None:
    slabs = [p.createMultiBody(0, p.createCollisionShape(p.GEOM_BOX, halfExtents=[0.2, 0.2, 0.02],
                                                         physicsClientId=client),
                               basePosition=[0, 0, z], physicsClientId=client) for z in (0.9, 0.6, 0.3)]
    q = _Queries(client)
    hits = q.ray_hits([0.01, 0.02, 5.0], [0.01, 0.02, -1.0])
    assert [h.body for h in hits] == slabs
    casts = []
    cast = p.rayTest
    monkeypatch.setattr(p, "rayTest", lambda *a, **k: casts.append(1) or cast(*a, **k))
    assert q.first_ray_hit([0.01, 0.02, 5.0], [0.01, 0.02, -1.0]) == hits[0]
    n_first = len(casts)
    assert q.first_ray_hit([0.01, 0.02, 5.0], [0.01, 0.02, -1.0], skip={slabs[0]}) == hits[1]
    assert q.first_ray_hit([0.01, 0.02, 5.0], [0.01, 0.02, -1.0], skip=set(slabs)) is None
    casts.clear()
    q.ray_hits([0.01, 0.02, 5.0], [0.01, 0.02, -1.0])
    assert n_first < len(casts)  # the walk stopped at the first slab


def _box(client: int, half: list[float], z: float, mass: float = 0.0) -> int:
    return p.createMultiBody(mass, p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client),
                             basePosition=[0, 0, z], physicsClientId=client)


def test_jumping_skipped_bodies_finds_the_same_surface_with_fewer_casts(client, monkeypatch) -> None:
    table = _box(client, [0.3, 0.3, 0.02], 0.68)  # top at 0.70
    cube = _box(client, [0.025, 0.025, 0.025], 0.725, mass=0.1)  # resting on it
    hand = [_box(client, [0.04, 0.04, 0.01], z) for z in (0.85, 0.95, 1.05)]  # an "arm" above
    q = _Queries(client)
    start, end = [0.003, 0.004, 5.0], [0.003, 0.004, -1.0]
    casts = []
    cast = p.rayTest
    monkeypatch.setattr(p, "rayTest", lambda *a, **k: casts.append(a[0][2]) or cast(*a, **k))
    walked = q.first_ray_hit(start, end, skip={cube, *hand})
    n_walked = len(casts)
    casts.clear()
    jumped = q.first_ray_hit(start, end, skip={cube, *hand}, jump_skipped=True)
    assert walked is not None and jumped is not None
    assert walked.body == jumped.body == table
    assert jumped.position[2] == pytest.approx(walked.position[2], abs=1e-9)
    assert walked.position[2] == pytest.approx(0.70, abs=1e-3)
    # the hand's boxes were jumped: the first cast starts above the cube (outside every box)
    assert len(casts) < n_walked
    assert 0.75 < casts[0] < 0.84
    # the cube walked through as before (a hit on a skipped body is walked through)
    assert q.first_ray_hit(start, end, skip=set(hand), jump_skipped=True).body == cube
    # nothing but skipped bodies below: None
    assert q.first_ray_hit(start, end, skip={table, cube, *hand}, jump_skipped=True) is None


def test_a_body_not_skipped_above_the_skipped_ones_is_not_jumped(client) -> None:
    table = _box(client, [0.3, 0.3, 0.02], 0.68)
    hand = _box(client, [0.04, 0.04, 0.01], 0.85)
    shelf = _box(client, [0.3, 0.3, 0.01], 1.2)  # above the hand: the first surface not skipped
    q = _Queries(client)
    start, end = [0.003, 0.004, 5.0], [0.003, 0.004, -1.0]
    hit = q.first_ray_hit(start, end, skip={hand}, jump_skipped=True)
    assert hit == q.first_ray_hit(start, end, skip={hand})  # nothing to jump: the same walk, bit for bit
    assert hit is not None and hit.body == shelf
    assert q.first_ray_hit(start, end, skip={hand, shelf}, jump_skipped=True).body == table
    # a slanted ray: the same surface as the walk finds
    slant = q.first_ray_hit([0.2, 0.1, 2.0], [-0.1, -0.05, 0.0], skip={hand, shelf}, jump_skipped=True)
    assert slant is not None and slant.body == table
    walked = q.first_ray_hit([0.2, 0.1, 2.0], [-0.1, -0.05, 0.0], skip={hand, shelf})
    assert walked is not None and slant.position == pytest.approx(walked.position, abs=1e-9)
    assert slant.position[2] == pytest.approx(0.70, abs=1e-6)


def test_a_segments_floats_are_numpys_bits() -> None:
    """_segment's start, end, length and direction equal numpy's (asarray, norm of the difference,
    the difference over the length) bit for bit: vertical rays (the support queries', taken
    without numpy), rays along x or y, slanted ones, numpy scalars as coordinates, a zero length."""
    import numpy as np

    from robocfg.sim.queries import _segment

    rng = np.random.default_rng(3)
    cases = []
    for _ in range(3000):
        a = rng.uniform(-3, 3, 3) * 10.0 ** rng.integers(-6, 3)
        b = a.copy()
        moving = rng.choice(3, size=int(rng.integers(1, 4)), replace=False)
        b[moving] = rng.uniform(-6, 6, len(moving)) * 10.0 ** rng.integers(-8, 2)
        cases.append((list(a), list(b)))  # numpy float64 coordinates, as the queries pass them
    cases += [([0.1, 0.2, 5.0], [0.1, 0.2, -1.0]), ([0.0, -0.0, 1.0], [-0.0, 0.0, 1.0]), ([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])]
    for start, end in cases:
        a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        length = float(np.linalg.norm(b - a))
        got = _segment(start, end)
        assert got[0] == a.tolist() and got[1] == b.tolist()
        assert got[2] == length
        if length != 0.0:
            assert np.array_equal(np.array(got[3]), (b - a) / length)
    with pytest.raises(ValueError):
        _segment([0.0, 0.0], [1.0, 1.0])
