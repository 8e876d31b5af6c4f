"""SceneQueries.touching: one contact query of a's contacts with b, sorted by link, answers as one
query per link did (PyBullet puts the asked body first in each contact point)."""

from __future__ import annotations

import pybullet as p
import pytest
from _sim_helpers import PANDA, make_task

from robocfg.sim.world import World

CUBE = {"name": "cube", "shape": "box", "size": [0.05, 0.05, 0.05], "mass": 0.2, "position": [0.6, 0.3, 0.2]}


@pytest.fixture()
def world(tmp_path):
    with World(make_task(tmp_path, PANDA, objects=[CUBE])) as w:
        w.step(1)
        yield w


def test_touching_with_one_query_answers_as_one_query_per_link(world):
    """A cube falling onto the ground and resting there; the robot's links against the ground, all
    of them and one at a time: the same answer as asking link by link, both answers seen."""

    def per_link(a, b, links):
        return any(c[8] <= 0.0 for link in links for c in p.getContactPoints(a, b, link, physicsClientId=world.client))

    robot, cube, ground = world.robot, world.bodies["cube"], world.bodies["ground"]
    link_sets = [[-1], *[[i] for i in robot.link_index.values()], list(robot.link_index.values())]
    answers = []
    for _ in range(60):
        world.step(2)
        for a, links in [(cube, [-1]), (cube, [0]), *((robot.body_id, links) for links in link_sets)]:
            got = world.touching(a, ground, links)
            assert got == per_link(a, ground, links)
            answers.append(got)
    assert True in answers and False in answers  # both answers were checked
