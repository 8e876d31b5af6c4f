"""World.play: the same motor commands and physics as ``arm.command`` + ``step()`` per row."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from _sim_helpers import PANDA, make_task

from robocfg.errors import RunInterrupted
from robocfg.sim.world import World


def _rows(arm, n: int = 120) -> tuple[np.ndarray, np.ndarray]:
    """A smooth move away from home: (n, joints) targets and their velocities."""
    s = np.linspace(0.0, 1.0, n)[:, None]
    q = arm.home + 0.4 * (3 * s**2 - 2 * s**3)
    return q, np.gradient(q, axis=0) * 240.0


def _state(world: World) -> list[tuple[float, float]]:
    r = world.robot
    return [(s[0], s[1]) for s in p.getJointStates(r.body_id, r._movable_indices, physicsClientId=world.client)]


def _run(tmp_path, how: str, stop_at: int | None = None):
    """Play the rows with the gripper closing meanwhile, a step hook watching the clock and,
    with ``stop_at``, a stop request answered at that step."""
    task = make_task(tmp_path, PANDA)
    with World(task) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm)
        seen: list[int] = []
        hooked: list[tuple[int, float]] = []
        w.step_hooks.append(lambda: hooked.append((w.steps, w.t)))
        if stop_at is not None:
            w.should_stop = lambda: w.steps >= stop_at
        arm.gripper.close()
        stopped = None
        try:
            if how == "play":
                w.play(arm, q, qd, after=lambda: seen.append(w.steps))
            else:
                for row, v in zip(q.tolist(), qd.tolist(), strict=True):
                    arm.command(row, v)
                    w.step()
                    seen.append(w.steps)
        except RunInterrupted as exc:
            stopped = (w.steps, str(exc))
        w.should_stop = None
        w.step(24)  # the drives hold the last target afterwards
        drives = w.robot.drives
        return (_state(w), seen, hooked, stopped,
                [(drives[j].target, drives[j].target_velocity) for j in arm.joints], w.t)


def test_play_is_bit_for_bit_the_per_step_loop(tmp_path):
    played = _run(tmp_path, "play")
    looped = _run(tmp_path, "loop")
    assert played == looped  # exact floats: the same commands reached the same physics
    state, seen, hooked, stopped, *_ = played
    assert seen == list(range(1, 121)) and hooked[:120] == [(k, k * (1 / 240)) for k in range(1, 121)]
    assert stopped is None
    moved = [abs(a - b) for (a, _), (b, _) in zip(state[:7], _state_at_home(tmp_path)[:7], strict=True)]
    assert max(moved) > 0.1  # the arm really moved (the rows were not ignored)


def test_play_answers_a_stop_request_like_step(tmp_path):
    played, looped = _run(tmp_path, "play", stop_at=50), _run(tmp_path, "loop", stop_at=50)
    assert played == looped
    assert played[3] is not None and played[3][0] == 50  # at the first check at or after step 50


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
