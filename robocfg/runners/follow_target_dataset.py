"""``run follow-target --dataset``: the run recorded as episode 0, and its replay.

The reactive controller's joint targets (one QP step per control period) go through the dataset's
command gate like every kind's commands (:mod:`robocfg.datasets.gate`): the recorded actions are
the controller's latest commanded joint positions at each dataset frame (the gripper command is
held open). Being closed-loop, the controller sees the lag the gate adds (one frame, ramped) and
corrects for it; the tracking figures of a recorded run include it (the report says so).

Replay rebuilds the world as the run did (:class:`FollowLoop`: the same obstacles, marker and
start), moves the moving obstacles at the same control periods, measures the TCP against the
target after each period as the run does, and judges the outcome by the run's own rule
(``reached``: RMS error after settling, or the final error of a target at rest, within the
tolerances). The controller is built but not stepped: the recorded actions drive the arm.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING

from robocfg.engine.dataset import EpisodeSink, EpisodeTap, ReplayScene

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.runners.follow_target_loop import FollowLoop
    from robocfg.runners.follow_target_report import FollowTargetResult
    from robocfg.sim.world import World

PHASES = ("settle", "track")  # before settle_time (not in the tracking statistics), then tracking
LAG_WARNING = ("--dataset: the controller's joint targets reach the drives through the recorded actions (latched at "
               "the dataset rate, ramped linearly between frames, one frame late), so the tracking errors include "
               "that lag")


def begin(sink: EpisodeSink, world: World, run: FollowLoop) -> EpisodeTap:
    """Start recording ``run`` (its world built, the controller ready, nothing stepped yet)."""
    from robocfg.datasets.language import follow_target_instruction

    settle = run.params.settle_time
    run.result.warnings.append(LAG_WARNING)
    tap = sink.begin(world, run.arm, None, lambda: PHASES[world.t >= settle], PHASES,
                     follow_target_instruction(run.params.motion, len(run.obstacle_ids)))
    run.lead = tap.lag_steps * world.dt
    return tap


def end(sink: EpisodeSink, tap: EpisodeTap, seed: int, result: FollowTargetResult) -> None:
    """Close the recording with the run's tracking outcome (success = the target was reached)."""
    tap.stop()
    if result.failed_phase is not None:
        sink.end(tap, 0, seed, False, result.failed_phase, result.reason or "")
    elif result.reached:
        sink.end(tap, 0, seed, True, None, "reached")
    else:
        sink.end(tap, 0, seed, False, "track", result.unreachable_reason or "not reached")


@contextmanager
def replay_scene(task: CheckedTask, loop_for: Callable[[World], FollowLoop]) -> Iterator[ReplayScene]:
    """The run's world as its recording began (``loop_for(world)`` builds the run's
    :class:`FollowLoop` in it); a step hook moves the obstacles and measures as the control loop
    does; ``judge()`` → (reached, reason)."""
    from robocfg.sim.world import World

    with World(task) as world:
        run = loop_for(world)
        start, n = world.steps, run.n_sub
        periods = max(1, round(run.params.duration / run.ctrl_dt))

        def period_end() -> None:
            k, r = divmod(world.steps - start, n)
            if r or k > periods:
                return
            run._measure(None)
            run._move_obstacles(world.t + run.ctrl_dt)

        run._move_obstacles(world.t + run.ctrl_dt)
        world.step_hooks.append(period_end)

        def judge() -> tuple[bool, str]:
            r = run.finish(None, time.perf_counter())
            measured = "" if r.position_error_mm is None else f", RMS {r.position_error_mm.rms:.2f} mm after settling"
            measured += f", final {r.final_position_error_mm:.2f} mm" if r.final_position_error_mm is not None else ""
            if r.min_clearance_mm is not None:
                measured += f", min clearance {r.min_clearance_mm:.2f} mm, {r.contacts} contacts"
            # not why (blocked, QP failures: the controller's own figures; it does not run here)
            return (True, f"reached{measured}") if r.reached else (False, f"track: not reached{measured}")

        yield ReplayScene(world, run.arm, None, judge)
