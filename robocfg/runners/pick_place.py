"""``run pick-place``: pick the task's object and place it, robot-agnostic, over seeded episodes.

Episode k randomises the object (position, yaw, mass, friction) and the place point with
``default_rng([seed, k])`` and runs the 8-phase state machine of
:mod:`robocfg.runners.pick_place_machine` in the session's world, restored before each episode.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from robocfg.config.commands import Limits, PickPlaceParams
from robocfg.config.robot import ParallelGripperConfig
from robocfg.engine.dataset import ReplayScene
from robocfg.engine.options import FrameRecorder, RunOptions
from robocfg.engine.randomize import place_randomly
from robocfg.engine.registry import register_task
from robocfg.engine.session import BatchTiming, EpisodeSession, EpisodicRunner, episode_rng
from robocfg.motion.moves import MoveFailed, bound_ik_by_iterations
from robocfg.runners.pick_place_command import PickPlaceCommand
from robocfg.runners.pick_place_machine import _StateMachine
from robocfg.runners.pick_place_report import EpisodeResult, PickPlaceReport, summarise
from robocfg.runners.pick_place_setup import (
    EpisodeSetup,
    _Tools,
    not_simulated,
    planned_drive,
    reactive_drive,
)

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask

__all__ = ["EpisodeSetup", "PickPlaceRunner", "_StateMachine", "_Tools", "episode_setup", "episode_setups",
           "run_pick_place"]

PickPlaceTiming = BatchTiming


def episode_setup(params: PickPlaceParams, seed: int, k: int) -> EpisodeSetup:
    """Episode ``k``'s randomised object (pose, mass, friction) and place point, a fixed function
    of (seed, k): the object is placed first, then the place point, mass and friction are drawn."""
    rz = params.randomize
    rng = episode_rng(seed, k)
    placed = place_randomly(params.object, rz.object, rng)
    px, py = (rng.uniform(-1, 1, 2) * np.asarray(rz.place.xy_range))
    obj = params.object
    mass = obj.mass * (1 + rng.uniform(-1, 1) * rz.mass_scale)
    friction = obj.friction * (1 + rng.uniform(-1, 1) * rz.friction_scale)
    body = placed.body.model_copy(update={"mass": mass, "friction": friction})
    yaw = math.radians((obj.euler_deg or [0, 0, 0])[2]) + placed.yaw
    place = np.asarray(params.place_position[:2]) + np.array([px, py])
    return EpisodeSetup(k, seed + k, body, yaw, place)


def episode_setups(params: PickPlaceParams, seed: int, episodes: int) -> list[EpisodeSetup]:
    """The setups of episodes 0 .. ``episodes`` − 1."""
    return [episode_setup(params, seed, k) for k in range(episodes)]


class PickPlaceSession(EpisodeSession[EpisodeResult]):
    """The pick-place world, kinematic model and limits, shared by every episode."""

    phases = ("setup", "pre_grasp", "approach", "grasp", "lift", "transport", "lower", "release", "retract")

    def __init__(self, task: CheckedTask, options: RunOptions, timing: BatchTiming | None = None):
        from robocfg.motion.placement import resolve_placement, with_stand

        # Before the world is built: placement: auto may raise the work surface (a stand in the scene).
        self.placement = resolve_placement(task, task.robots[0].config.arm(options.arm).name)
        super().__init__(with_stand(task, self.placement.stand), options, timing)

    def prepare(self) -> None:
        from robocfg.assets.object_shape import object_shape
        from robocfg.checks.grip_force import pad_force
        from robocfg.grasp.gripper_model import measure_gripper
        from robocfg.kinematics.model import KinematicModel
        from robocfg.motion.limits import limits_from_robot

        robot = self.task.robots[0]
        self.arm_cfg = robot.config.arm(self.options.arm)
        placement = self.placement
        self.params: PickPlaceParams = placement.params  # world positions
        self.placement_note = placement.note
        self.handle = self.world.robot.arm(self.arm_cfg.name)
        shape = object_shape(self.params.object, self.task.path.parent)
        obj = self.params.object
        if shape.file_mass is not None and "mass" not in obj.model_fields_set:  # the URDF's own mass
            self.params = self.params.model_copy(update={"object": obj.model_copy(update={"mass": shape.file_mass})})
        # Poses out of reach (IK, before simulating): a nominal one fails every episode unsimulated.
        self.reach = placement.reach
        self.blocked = next((r for r in self.reach if r.nominal), None)
        model = KinematicModel.from_robot(robot, arm=self.arm_cfg.name, base_pose=self.world.robot.base_pose())
        bound_ik_by_iterations(model)  # same seed ⇒ same answers, whatever the machine load
        scale = self.params.speed_scale
        boxes = measure_gripper(self.world.robot, self.handle) if isinstance(self.arm_cfg.gripper, ParallelGripperConfig) else None
        force = pad_force(robot, self.arm_cfg)
        self.tools = _Tools(model, limits_from_robot(robot, self.handle.joints,
                                                     Limits(velocity_scale=scale, acceleration_scale=scale)),
                            reactive_drive(robot, self.world, self.arm_cfg.name, self.params, shape),
                            planned_drive(robot, self.world, model, self.params), shape=shape, boxes=boxes,
                            pad_force=force)

    def _machine(self, k: int, recorder: FrameRecorder | None) -> _StateMachine:
        """Episode ``k``'s state machine in the restored world (it spawns the object, removed
        before the next restore). The object is a new body each episode, not one made once and
        reset in place: a body made before the snapshot and reset gave episode 0 of
        ``pick_place --robot xarm6 --seed 5`` other physics when it ran first in a session than
        after another episode (tests/test_engine.py)."""
        setup = episode_setup(self.params, self.seed, k)
        self.remove_after_episode(setup.body.name)
        return _StateMachine(self.world, self.handle, self.tools, self.params, setup, recorder, self.log_for(k))

    def episode(self, k: int, recorder: FrameRecorder | None) -> EpisodeResult:
        if self.blocked is not None:
            setup = episode_setup(self.params, self.seed, k)
            return not_simulated(setup, self.blocked.phase, f"{self.blocked.reason}; checked before simulating")
        sm = self._machine(k, recorder)
        self.record_from(self.handle, sm.obj, lambda: sm.mover.phase, self._instruction)
        try:
            sm.run()
            failed, reason = None, "placed"
        except MoveFailed as exc:
            failed, reason = exc.phase, exc.reason
            sm.close_phase(False, reason)
        return sm.result(failed, reason)

    def _instruction(self) -> str:
        """The episode's language instruction (asked only when a dataset records it)."""
        from robocfg.datasets.language import pick_place_instruction

        return pick_place_instruction(self.params)

    def scene(self, k: int) -> ReplayScene:
        sm = self._machine(k, None)

        def judge() -> tuple[bool, str]:
            try:
                sm._check_placed()
                return True, "placed"
            except MoveFailed as exc:
                return False, f"{exc.phase}: {exc.reason}"

        return ReplayScene(self.world, self.handle, sm.obj, judge)

    def report(self, records: list[EpisodeResult], interrupted: bool) -> PickPlaceReport:
        skipped = self.tools.reactive.skipped if self.tools.reactive is not None else []
        warnings = [w.format() for w in self.task.warnings]
        warnings += [f"obstacle {name!r} is a mesh: the reactive controller does not avoid it" for name in skipped]
        unseen = self.tools.planned.skipped if self.tools.planned is not None else []
        warnings += [f"body {name!r} is a mesh: the planner does not avoid it" for name in unseen]
        warnings += [r.problem(self.task).format() for r in self.reach]
        warnings += [self.placement_note] if self.placement_note else []
        return PickPlaceReport(task=str(self.task.path), robot=self.task.robots[0].config.name,
                               arm=self.arm_cfg.name, seed=self.seed, summary=summarise(records), episodes=records,
                               warnings=warnings, interrupted=interrupted)


@register_task
class PickPlaceRunner(PickPlaceCommand, EpisodicRunner):
    params = PickPlaceParams
    report = PickPlaceReport

    def open_session(self) -> PickPlaceSession:
        return PickPlaceSession(self.task, self.options)


def run_pick_place(task, episodes: int = 1, seed: int | None = None, arm: str | None = None,
                   gui: bool = False, record: Callable[[Any], FrameRecorder] | None = None, record_episode: int = 0,
                   log: Callable[[str], None] | None = None,
                   on_episode: Callable[[EpisodeResult], None] | None = None,
                   sink: Any = None, should_stop: Callable[[], bool] | None = None) -> tuple[PickPlaceReport, BatchTiming]:
    """``episodes`` episodes of a pick-place task; (report, wall-clock timing). Keyword form of
    ``PickPlaceRunner(task, RunOptions(...)).run()`` kept for scripts and benchmarks; ``record``
    is a recorder factory ``world -> recorder`` for episode ``record_episode``."""
    options = RunOptions(seed=seed, episodes=episodes, arm=arm, gui=gui, recorder=record, record_episode=record_episode,
                         log=log, on_episode=on_episode, sink=sink, should_stop=should_stop)  # type: ignore[arg-type]
    out = PickPlaceRunner(task, options).run()
    return out.report, out.timing
