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
