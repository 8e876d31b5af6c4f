"""Playing a sampled joint trajectory: one motor call and one physics step per sample.

``play_rows(world, arm, q, qd, after)`` sends, before physics step k, the position targets
``q[k]`` (rad or m) and target velocities ``qd[k]`` (rad/s or m/s) of the arm's joints, then steps
the world (grippers, periodic divergence check and step hooks included) and calls ``after()``.
It sends exactly what ``arm.command(q[k], qd[k])`` followed by
``world.step()`` sends, in one ``setJointMotorControlArray`` per step with the motor settings
looked up once per trajectory instead of per step: robocfg's per-step cost while an arm moves.

It falls back to exactly that per-row loop where the fast path does not apply: an arm whose
``command`` is intercepted (a dataset's command gate), or joints with a speed cap or no drive yet.
The drives' recorded targets (``RobotHandle.drives``) end at the last row sent, as per row.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import pybullet as p

from robocfg.errors import RunInterrupted

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle
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
    token, idx, kp, kd, force, drives = plan
    body, client, mode = robot.body_id, robot.client, p.POSITION_CONTROL
    send, tokens = p.setJointMotorControlArray, robot.drive_token
    # World._advance, inlined (keep the two in step): physics step, clock, grippers, the periodic
    # divergence check and stop request, step hooks. Locals instead of attribute lookups: this loop
    # runs once per physics step and is most of robocfg's per-step cost.
    stepsim, clock, dt, every = p.stepSimulation, time.perf_counter, world.dt, world._check_every
    grippers, hooks = world._grippers, world.step_hooks
    sent: tuple[list[float], list[float]] | None = None
    physics = 0.0
    try:
        for row, speeds in zip(q_rows, qd_rows):  # noqa: B905 - shapes checked above
            if tokens(key) is not token:  # a drive of the arm was replaced (new gains): as command() would
                plan = robot.motor_plan(key)
                if plan is None:
                    arm.command(row, speeds)
                    sent = None
                else:
                    token, idx, kp, kd, force, drives = plan
            if plan is not None:
                send(body, idx, mode, targetPositions=row, targetVelocities=speeds, positionGains=kp,
                     velocityGains=kd, forces=force, physicsClientId=client)
                sent = (row, speeds)
            t0 = clock()
            stepsim(physicsClientId=client)
            physics += clock() - t0
            world.steps = steps = world.steps + 1
            world.t = steps * dt
            for g in grippers:
                g.update()
            if steps % every == 0:
                world._check()
                if world.should_stop is not None and world.should_stop():
                    raise RunInterrupted("simulation", "SIGINT/SIGTERM")
            for hook in hooks:
                hook()
            if after is not None:
                after()
    finally:
        world.physics_seconds += physics
        if sent is not None:  # the drives remember the last targets sent, as command() leaves them
            for d, v, w in zip(drives, *sent):  # noqa: B905 - shapes checked above
                d.target, d.target_velocity = v, w
