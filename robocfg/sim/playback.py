"""Playing a sampled joint trajectory: one motor call and one physics step per sample.

``play_rows(world, arm, q, qd, after)`` sends, before physics step k, the position targets
``q[k]`` (rad or m) and target velocities ``qd[k]`` (rad/s or m/s) of the arm's joints, then steps
the world (grippers, periodic divergence check and step hooks included) and calls ``after()``.
It sends exactly what ``arm.command(q[k], qd[k])`` followed by ``world.step()`` sends, in one
``setJointMotorControlArray`` per step with the motor settings looked up once per trajectory
instead of per step: robocfg's per-step cost while an arm moves.

Three loops, the same commands and steps in each:

* **bare** — nothing but physics runs between two samples (no ``after``, no step hooks, no gripper
  with a target still moving: :meth:`~robocfg.sim.gripper.base.Gripper.busy`): per step one motor
  call with its arguments prepared once and one ``stepSimulation``; the clock, the periodic
  divergence check and the stop request are done once per check period (every
  ``World.check_every`` steps, at the same steps as :meth:`World.step`). Nothing in that loop can
  change a gripper's or a drive's state, so skipping the no-op gripper updates is exact.
* **hooked** — per step as :meth:`World.step` does it, with the motor settings re-read when a drive
  of the arm was replaced (by a hook, ``after`` or a gripper update).
* **through** — an arm whose ``command`` is intercepted (a dataset's command gate) is played by the
  interceptor's ``World.play_through`` when it offers one (:meth:`robocfg.datasets.recorder.EpisodeRecorder.play`).
* **per row** — ``arm.command`` then ``world.step`` per row, where the fast paths do not apply: an
  intercepted command without ``play_through``, or joints with a speed cap or no drive yet.

``advance_idle(world, n)`` is the bare loop without motor calls (``World.step`` uses it while no
hook or busy gripper needs the steps one by one). The drives' recorded targets
(``RobotHandle.drives``) end at the last row sent, as per row.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Protocol

import numpy as np
import pybullet as p

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle, Drive, MotorPlan
    from robocfg.sim.world import World


def play_rows(world: World, arm: ArmHandle, q: np.ndarray, qd: np.ndarray,
              after: Callable[[], None] | None = None) -> None:
    """See the module docstring. ``q``, ``qd``: (steps, arm joints) arrays, arm-joint order."""
    robot, key = arm.robot, tuple(arm.joints)
    q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
    if q.ndim != 2 or q.shape[1] != len(key) or qd.shape != q.shape:
        raise ValueError(f"targets of shape {q.shape} and velocities of shape {qd.shape} for {len(key)} arm joints")
    intercepted = "command" in vars(arm)
    plan = None if intercepted else robot.motor_plan(key)
    if plan is not None and after is None and world.idle():
        _play_bare(world, arm, plan, np.ascontiguousarray(q), np.ascontiguousarray(qd))  # read as bytes
        return
    q_rows, qd_rows = q.tolist(), qd.tolist()  # once, not per step
    if intercepted and world.play_through is not None and world.play_through(arm, q_rows, qd_rows, after):
        return
    if plan is None:
        for row, speeds in zip(q_rows, qd_rows):  # noqa: B905 - shapes checked above
            arm.command(row, speeds)
            world.step()
            if after is not None:
                after()
        return
    _play_hooked(world, arm, plan, q_rows, qd_rows, after)


def _play_bare(world: World, arm: ArmHandle, plan: MotorPlan, q: np.ndarray, qd: np.ndarray) -> None:
    """The bare loop (module docstring): one motor call and one physics step per row. Each step's
    targets and velocities reach PyBullet as two tuples of Python floats read straight from the
    arrays' bytes (``struct.iter_unpack``, native doubles: the same floats as ``tolist``), made as
    the step comes and freed after it, so they come back from Python's float free list, in cache;
    no list of a move's floats is ever built. The divergence check and the stop request come every
    ``world.check_every`` steps (a countdown), as in :meth:`World.step`. The physics steps are timed
    only while ``world.time_physics``."""
    _, idx, kp, kd, force, drives = plan
    robot = arm.robot
    body, client, mode = robot.body_id, robot.client, p.POSITION_CONTROL
    send, stepsim, clock = p.setJointMotorControlArray, p.stepSimulation, time.perf_counter
    every, dt, timed = world.check_every, world.dt, world.time_physics
    unpack = struct.Struct(f"{q.shape[1]}d").iter_unpack  # native doubles: numpy's float64 layout
    base = world.steps  # the world's steps at the last check (or at the start)
    left = mark = every - base % every  # steps to the next check, and that distance from base
    physics = 0.0
    row = speeds = None
    try:
        # positional: setJointMotorControlArray(body, joints, mode, targetPositions,
        # targetVelocities, forces, positionGains, velocityGains, physicsClientId)
        # Two copies of one loop, with and without the physics clock, so that the untimed one (a
        # user's run) tests nothing per step for it; keep the two in step.
        if timed:
            for row, speeds in zip(unpack(q.data), unpack(qd.data)):  # noqa: B905 - shapes checked by play_rows
                send(body, idx, mode, row, speeds, force, kp, kd, client)
                t0 = clock()
                stepsim(client)
                physics += clock() - t0
                left -= 1
                if not left:
                    base += mark
                    left = mark = every
                    world.steps, world.t = base, base * dt
                    world.periodic_check()
        else:
            for row, speeds in zip(unpack(q.data), unpack(qd.data)):  # noqa: B905 - shapes checked by play_rows
                send(body, idx, mode, row, speeds, force, kp, kd, client)
                stepsim(client)
                left -= 1
                if not left:
                    base += mark
                    left = mark = every
                    world.steps, world.t = base, base * dt
                    world.periodic_check()
    finally:  # the steps taken (a step that raised is not), also when stopped or diverged
        steps = base + mark - left
        world.steps, world.t = steps, steps * dt
        world.physics_seconds += physics
        if row is not None and speeds is not None:  # the drives remember the last targets sent, as command() leaves them
            _remember(drives, row, speeds)


def _play_hooked(world: World, arm: ArmHandle, plan: MotorPlan, q_rows: list, qd_rows: list,
                 after: Callable[[], None] | None) -> None:
    """The hooked loop (module docstring): :meth:`World.step`'s bookkeeping inlined, per step."""
    robot, key = arm.robot, tuple(arm.joints)
    token, idx, kp, kd, force, drives = plan
    current: MotorPlan | None = plan
    body, client, mode = robot.body_id, robot.client, p.POSITION_CONTROL
    send, tokens = p.setJointMotorControlArray, robot.drive_token
    # World._advance, inlined (keep the two in step): physics step, clock, grippers, the periodic
    # divergence check and stop request, step hooks.
    stepsim, clock, dt, every = p.stepSimulation, time.perf_counter, world.dt, world.check_every
    grippers, hooks, timed = world.grippers, world.step_hooks, world.time_physics
    sent: tuple[list[float], list[float]] | None = None
    physics = 0.0
    try:
        for row, speeds in zip(q_rows, qd_rows):  # noqa: B905 - shapes checked by play_rows
            if tokens(key) is not token:  # a drive of the arm was replaced (new gains): as command() would
                current = robot.motor_plan(key)
                if current is None:
                    arm.command(row, speeds)
                    sent = None
                else:
                    token, idx, kp, kd, force, drives = current
            if current is not None:
                send(body, idx, mode, row, speeds, force, kp, kd, client)
                sent = (row, speeds)
            if timed:
                t0 = clock()
                stepsim(client)
                physics += clock() - t0
            else:
                stepsim(client)
            world.steps = steps = world.steps + 1
            world.t = steps * dt
            for g in grippers:
                g.update()
            if steps % every == 0:
                world.periodic_check()
            for hook in hooks:
                hook()
            if after is not None:
                after()
    finally:
        world.physics_seconds += physics
        if sent is not None:
            _remember(drives, *sent)


def advance_idle(world: World, n: int) -> None:
    """``n`` physics steps while nothing but physics runs (``world.idle()``): the clock and the
    periodic divergence check and stop request at the same steps as ``n`` calls of ``World.step``
    (the steps timed only while ``world.time_physics``)."""
    client, stepsim, clock = world.client, p.stepSimulation, time.perf_counter
    every, steps, timed = world.check_every, world.steps, world.time_physics
    physics, done, k = 0.0, 0, 0
    try:
        while done < n:
            m = min(n - done, every - steps % every)
            try:
                if timed:
                    for k in range(m):  # noqa: B007 - k is read when a step raises
                        t0 = clock()
                        stepsim(client)
                        physics += clock() - t0
                else:
                    for k in range(m):  # noqa: B007 - k is read when a step raises
                        stepsim(client)
            except BaseException:  # stopped inside the chunk: its steps before k were taken
                world.steps = steps + k
                world.t = world.steps * world.dt
                raise
            done += m
            steps += m
            world.steps, world.t = steps, steps * world.dt
            if steps % every == 0:
                world.periodic_check()
    finally:
        world.physics_seconds += physics


class Latched(Protocol):
    """What :func:`play_latched` reads of a command gate (:class:`robocfg.datasets.gate.CommandGate`)."""

    q_wanted: np.ndarray | list[float]  # the runner's latest arm command (latched at the next frame)
    ramp: list[list[float]]  # this interval's arm targets for its steps 1..n (rad or m)
    slope: list[float]  # their target velocity (rad/s or m/s)
    moving: bool  # False: the held target is sent at the interval's first step only

    def drive(self, j: int) -> None: ...  # send step j's targets through the arm's own command


def play_latched(world: World, arm: ArmHandle, q_rows: list, gate: Latched, steps_per_frame: int,
                 frame: Callable[[], None], after: Callable[[], None] | None) -> bool:
    """Rows played through a command gate (a recorded episode) as ``arm.command(row)`` +
    ``world.step()`` per row do while the gate's recorder is the only step hook: per step the row
    becomes the gate's wish, physics steps, grippers update, the periodic check, a frame every
    ``steps_per_frame`` steps (``frame()``: latch and sample), then the gate's ramp target of the
    next step is sent (one motor call, settings looked up once; the gate's own ``drive`` when the
    arm's drives have no fast plan). False (nothing played) when the arm's joints have none."""
    robot, key = arm.robot, tuple(arm.joints)
    plan = robot.motor_plan(key)
    if plan is None:
        return False
    token, idx, kp, kd, force, drives = plan
    current: MotorPlan | None = plan
    body, client, mode = robot.body_id, robot.client, p.POSITION_CONTROL
    send, tokens = p.setJointMotorControlArray, robot.drive_token
    stepsim, clock, dt, every, n = p.stepSimulation, time.perf_counter, world.dt, world.check_every, steps_per_frame
    grippers, timed = world.grippers, world.time_physics
    sent: tuple[list[float], list[float]] | None = None
    physics = 0.0
    try:
        for row in q_rows:
            gate.q_wanted = row
            if timed:
                t0 = clock()
                stepsim(client)
                physics += clock() - t0
            else:
                stepsim(client)
            world.steps = steps = world.steps + 1
            world.t = steps * dt
            for g in grippers:
                g.update()
            if steps % every == 0:
                world.periodic_check()
            j = steps % n
            if j == 0:
                frame()
            if j == 0 or gate.moving:  # the gate's drive(j + 1), inlined
                if tokens(key) is not token:  # a drive was replaced (a gripper command at the frame)
                    current = robot.motor_plan(key)
                    if current is not None:
                        token, idx, kp, kd, force, drives = current
                if current is None:
                    gate.drive(j + 1)
                    sent = None
                else:
                    sent = (gate.ramp[j], gate.slope)
                    send(body, idx, mode, sent[0], sent[1], force, kp, kd, client)
            if after is not None:
                after()
    finally:
        world.physics_seconds += physics
        if sent is not None:
            _remember(drives, *sent)
    return True


def _remember(drives: list[Drive], row: Sequence[float], speeds: Sequence[float]) -> None:
    for d, v, w in zip(drives, row, speeds):  # noqa: B905 - one per arm joint
        d.target, d.target_velocity = v, w
