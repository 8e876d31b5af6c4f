"""World.play: the same motor commands and physics as ``arm.command`` + ``step()`` per row."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from _sim_helpers import PANDA, make_task

from robocfg.sim.world import World


def _rows(arm, n: int = 120) -> tuple[np.ndarray, np.ndarray]:
    """A smooth move away from home: (n, joints) targets and their velocities."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    q = arm.home + 0.4 * (3 * s**2 - 2 * s**3)
    return q, np.gradient(q, axis=0) * 240.0


def _state(world: World) -> list[tuple[float, float]]:
    r = world.robot
    return [(s[0], s[1]) for s in p.getJointStates(r.body_id, r._movable_indices, physicsClientId=world.client)]


def _run(tmp_path, how: str):
    task = make_task(tmp_path, PANDA)
    with World(task) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm)
        seen: list[int] = []
        if how == "play":
            w.play(arm, q, qd, after=lambda: seen.append(w.steps))
        else:
            for row, v in zip(q.tolist(), qd.tolist(), strict=True):
                arm.command(row, v)
                w.step()
                seen.append(w.steps)
        w.step(24)  # the drives hold the last target afterwards
        drives = w.robot.drives
        return _state(w), seen, [(drives[j].target, drives[j].target_velocity) for j in arm.joints], w.t


def test_play_is_bit_for_bit_the_per_step_loop(tmp_path):
    played, steps_a, drives_a, t_a = _run(tmp_path, "play")
    looped, steps_b, drives_b, t_b = _run(tmp_path, "loop")
    assert played == looped  # exact floats: the same commands reached the same physics
    assert steps_a == steps_b == list(range(1, 121))  # after() ran after every step
    assert drives_a == drives_b and t_a == t_b
    moved = [abs(a - b) for (a, _), (b, _) in zip(played[:7], _state_at_home(tmp_path)[:7], strict=True)]
    assert max(moved) > 0.1  # the arm really moved (the rows were not ignored)


def _state_at_home(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        w.step(144)
        return _state(w)


def test_play_goes_through_an_intercepted_command(tmp_path):
    """An arm whose ``command`` is replaced (a dataset's command gate) gets every row through it."""
    with World(make_task(tmp_path, PANDA)) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm, 10)
        got: list[list[float]] = []
        arm.command = lambda row, v=None: got.append(list(row))  # type: ignore[method-assign]
        w.play(arm, q, qd)
        assert got == q.tolist() and w.steps == 10


def test_play_rejects_mismatched_rows(tmp_path):
    with World(make_task(tmp_path, PANDA)) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm, 5)
        with pytest.raises(ValueError, match="shape"):
            w.play(arm, q, qd[:4])
        with pytest.raises(ValueError, match="shape"):
            w.play(arm, q[:, :6], qd[:, :6])
