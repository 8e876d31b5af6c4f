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
* **per row** — ``arm.command`` then ``world.step`` per row, where the fast paths do not apply: an
  arm whose ``command`` is intercepted (a dataset's command gate), or joints with a speed cap or
  no drive yet.

``advance_idle(world, n)`` is the bare loop without motor calls (``World.step`` uses it while no
hook or busy gripper needs the steps one by one). The drives' recorded targets
(``RobotHandle.drives``) end at the last row sent, as per row.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

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
    q_rows, qd_rows = q.tolist(), qd.tolist()  # once, not per step
    plan = None if "command" in vars(arm) else robot.motor_plan(key)
    if plan is None:
        for row, speeds in zip(q_rows, qd_rows):  # noqa: B905 - shapes checked above
            arm.command(row, speeds)
            world.step()
            if after is not None:
                after()
        return
    if after is None and world.idle():
        _play_bare(world, arm, plan, q_rows, qd_rows)
    else:
        _play_hooked(world, arm, plan, q_rows, qd_rows, after)


def _play_bare(world: World, arm: ArmHandle, plan: MotorPlan, q_rows: list, qd_rows: list) -> None:
    """The bare loop (module docstring): one motor call and one physics step per row."""
    _, idx, kp, kd, force, drives = plan
    robot = arm.robot
    body, client, mode = robot.body_id, robot.client, p.POSITION_CONTROL
    send, stepsim, clock = p.setJointMotorControlArray, p.stepSimulation, time.perf_counter
    every, steps, n = world.check_every, world.steps, len(q_rows)
    physics, i, j = 0.0, 0, -1
    try:
        while i < n:
            end = min(n, i + every - steps % every)  # the next check is after this chunk's last step
            try:
                for j in range(i, end):
                    # positional: setJointMotorControlArray(body, joints, mode, targetPositions,
                    # targetVelocities, forces, positionGains, velocityGains, physicsClientId)
                    send(body, idx, mode, q_rows[j], qd_rows[j], force, kp, kd, client)
                    t0 = clock()
                    stepsim(physicsClientId=client)
                    physics += clock() - t0
            except BaseException:  # stopped inside the chunk: steps i..j-1 were taken
                world.steps = steps + j - i
                world.t = world.steps * world.dt
                raise
            steps += end - i
            i = end
            world.steps, world.t = steps, steps * world.dt
            if steps % every == 0:
                world.periodic_check()
    finally:
        world.physics_seconds += physics
        if j >= 0:  # the drives remember the last targets sent, as command() leaves them
            _remember(drives, q_rows[j], qd_rows[j])


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
    grippers, hooks = world.grippers, world.step_hooks
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
            t0 = clock()
            stepsim(physicsClientId=client)
            physics += clock() - t0
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
    periodic divergence check and stop request at the same steps as ``n`` calls of ``World.step``."""
    client, stepsim, clock = world.client, p.stepSimulation, time.perf_counter
    every, steps = world.check_every, world.steps
    physics, done, k = 0.0, 0, 0
    try:
        while done < n:
            m = min(n - done, every - steps % every)
            try:
                for k in range(m):  # noqa: B007 - k is read when a step raises
                    t0 = clock()
                    stepsim(physicsClientId=client)
                    physics += clock() - t0
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


def _remember(drives: list[Drive], row: list[float], speeds: list[float]) -> None:
    for d, v, w in zip(drives, row, speeds):  # noqa: B905 - one per arm joint
        d.target, d.target_velocity = v, w
