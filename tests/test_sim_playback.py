"""World.play: the same motor commands and physics as ``arm.command`` + ``step()`` per row."""

from __future__ import annotations

import numpy as np
import pybullet as p
import pytest
from _sim_helpers import PANDA, make_task

from robocfg.errors import RobocfgError, RunInterrupted
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
    assert played[3] is not None and played[3][0] == 60  # at the first check at or after step 50


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


def _run_bare(tmp_path, how: str, *, stop_at: int | None = None, max_joint_velocity: float = 100.0,
              rate: float | None = None, idle_steps: int = 0):
    """Play the rows with nothing else running per step (no hook, no ``after``; the gripper busy
    only with ``rate``), either with ``play``/``step(n)`` or row by row; returns the state, the
    steps at which the divergence check ran, where a stop or a divergence ended it, the drives."""
    task = make_task(tmp_path, PANDA)
    with World(task, max_joint_velocity=max_joint_velocity) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm)
        checked: list[int] = []
        check = w._check
        w._check = lambda: (checked.append(w.steps), check())[1]  # type: ignore[method-assign]
        if stop_at is not None:
            w.should_stop = lambda: w.steps >= stop_at
        if rate is not None:
            arm.gripper.rate = rate
            arm.gripper.close()  # rate-limited: the target moves in update() after every step
        ended = None
        try:
            w.step(3)  # the play starts off the check grid
            if how == "fast":
                w.play(arm, q, qd)
                w.step(idle_steps)
            else:
                for row, v in zip(q.tolist(), qd.tolist(), strict=True):
                    arm.command(row, v)
                    w.step()
                for _ in range(idle_steps):
                    w.step()
        except RobocfgError as exc:
            ended = (type(exc).__name__, w.steps, w.t, str(exc))
        drives = w.robot.drives
        return (_state(w), w.steps, w.t, checked, ended,
                [(drives[j].target, drives[j].target_velocity) for j in arm.joints])


@pytest.mark.parametrize("case", [
    {},  # the bare loop: a move, then idle steps
    {"idle_steps": 37},
    {"stop_at": 50},  # a stop request answered at the same check
    {"max_joint_velocity": 0.05},  # the divergence check raises at the same step
    {"rate": 2.0, "idle_steps": 30},  # a busy gripper: updated after every step
])
def test_bare_loops_are_bit_for_bit_the_per_step_loop(tmp_path, case):
    fast, slow = _run_bare(tmp_path, "fast", **case), _run_bare(tmp_path, "slow", **case)
    assert fast == slow
    state, steps, t, checked, ended, _ = fast
    assert checked and all(s % 12 == 0 for s in checked)  # every 50 ms of simulated time at 240 Hz
    if "stop_at" in case:
        assert ended is not None and ended[:2] == ("RunInterrupted", 60)  # the first check at or after 50
    elif "max_joint_velocity" in case:
        assert ended is not None and ended[0] == "PhysicsDiverged" and ended[1] == checked[-1]
    else:
        assert ended is None and steps == 3 + 120 + case.get("idle_steps", 0) and t == steps / 240
    if "rate" in case:  # the closing fingers moved: the updates were not skipped
        assert state[7][0] < _state_at_home(tmp_path)[7][0] - 1e-3


def test_idle_world_skips_only_no_op_gripper_updates(tmp_path):
    """``World.idle``: false while a step hook is installed or a gripper's target still moves."""
    with World(make_task(tmp_path, PANDA)) as w:
        g = w.robot.arm().gripper
        assert w.idle() and not g.busy()
        g.rate = 1.0
        g.close()
        assert g.busy() and not w.idle()
        w.step(250)  # over 1 s at 1/s: the target has arrived
        assert not g.busy() and w.idle()
        w.step_hooks.append(lambda: None)
        assert not w.idle()


def _played_every_way(tmp_path, timed: bool) -> tuple[list, list[float]]:
    """A bare play, idle steps, a hooked play and single steps (every loop that steps the world),
    with the world's physics clock on or off: the joint states and ``physics_seconds`` after each."""
    with World(make_task(tmp_path, PANDA), time_physics=timed) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm, 60)
        states, seconds = [], []

        def done() -> None:
            states.append((_state(w), w.steps, w.t))
            seconds.append(w.physics_seconds)

        w.play(arm, q, qd)  # bare
        done()
        w.step(30)  # idle
        done()
        w.play(arm, q[::-1], -qd[::-1], after=lambda: None)  # hooked
        done()
        arm.gripper.rate = 2.0
        arm.gripper.close()
        w.step(20)  # per step (a busy gripper)
        done()
        return states, seconds


def test_physics_clock_is_opt_in_and_changes_nothing(tmp_path):
    """``World(time_physics=True)`` times every physics step (``physics_seconds``, for benchmarks);
    off (the default) nothing is timed, and the simulation is the same bit for bit either way."""
    untimed, seconds_off = _played_every_way(tmp_path, False)
    timed, seconds_on = _played_every_way(tmp_path, True)
    assert untimed == timed
    assert seconds_off == [0.0] * 4
    assert all(b > a for a, b in zip([0.0, *seconds_on], seconds_on, strict=False))  # each loop timed its steps


def _interrupted(tmp_path, monkeypatch, how: str, at: int):
    """Play the rows with ``stepSimulation`` raising KeyboardInterrupt on its ``at``-th call of the
    play (inside a check period): the world's clock and the drives' targets where it stopped."""
    with World(make_task(tmp_path, PANDA)) as w:
        arm = w.robot.arm()
        q, qd = _rows(arm)
        w.step(5)  # off the check grid
        calls = [0]
        step = p.stepSimulation

        def flaky(*a, **k):
            calls[0] += 1
            if calls[0] == at:
                raise KeyboardInterrupt
            return step(*a, **k)

        monkeypatch.setattr(p, "stepSimulation", flaky)
        with pytest.raises(KeyboardInterrupt):
            if how == "fast":
                w.play(arm, q, qd)
            else:
                for row, v in zip(q.tolist(), qd.tolist(), strict=True):
                    arm.command(row, v)
                    w.step()
        monkeypatch.setattr(p, "stepSimulation", step)
        drives = w.robot.drives
        return _state(w), w.steps, w.t, [(drives[j].target, drives[j].target_velocity) for j in arm.joints]


@pytest.mark.parametrize("at", [1, 7, 8, 50])
def test_bare_loop_stopped_inside_a_check_period_as_the_per_step_loop(tmp_path, monkeypatch, at):
    fast = _interrupted(tmp_path, monkeypatch, "fast", at)
    assert fast == _interrupted(tmp_path, monkeypatch, "slow", at)
    assert fast[1] == 5 + at - 1  # the steps before the one that raised
