"""Episodes: a world built once per process, restored before every episode, run by index.

An :class:`EpisodeSession` owns one :class:`~robocfg.sim.world.World` built from a checked task
and run options. Building it steps the world once, lets the kind prepare what every episode
shares (``prepare``: measure the gripper, build the IK model...) and takes a snapshot. ``run(k)``
then removes what the previous episode spawned, restores the snapshot (clock at zero, arms held,
grippers open), attaches the recorder when ``k`` is the filmed episode, and calls the kind's
``episode(k)`` — which draws its randomness from ``rng(k) = default_rng([seed, k])`` — so episode k
gives the same record whichever episodes ran before it, in this process or another.

A batch run is :func:`run_batch`: ``session.run(k)`` for k = 0, 1, ... until done or asked to
stop. Executors split that loop; ``robocfg.engine.run_episode(spec)`` runs one index anywhere.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar

import numpy as np

from robocfg import collector
from robocfg.engine.options import EpisodeOutcome, FrameRecorder, RunOptions
from robocfg.engine.runner import RunOutput, TaskRunner

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.config.scene import Body
    from robocfg.engine.dataset import EpisodeObjects, EpisodeTap, ReplayScene
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World

RecordT = TypeVar("RecordT", bound=EpisodeOutcome)


@dataclass
class BatchTiming:
    """Wall-clock figures of a batch (s); never part of the deterministic JSON report."""

    wall_time: float = 0.0
    per_episode: list[float] = field(default_factory=list)
    # s inside the physics engine's step; measured only with RunOptions.time_physics (0 otherwise)
    physics_per_episode: list[float] = field(default_factory=list)

    @property
    def mean_physics(self) -> float:
        n = len(self.physics_per_episode)
        return sum(self.physics_per_episode) / n if n else 0.0

    @property
    def mean_episode(self) -> float:
        return sum(self.per_episode) / len(self.per_episode) if self.per_episode else 0.0


def silent(_msg: str) -> None:
    """The log of an episode whose lines nobody reads (see :meth:`EpisodeSession.log_for`)."""


def episode_rng(seed: int, k: int) -> np.random.Generator:
    """The random stream of episode ``k`` of a run seeded ``seed`` (the same wherever it runs)."""
    return np.random.default_rng([seed, k])


class Session(Protocol):
    """What executors call: ``run(k)`` → episode k's record; ``close()`` frees the world."""

    def run(self, k: int) -> Any: ...

    def close(self) -> None: ...


class EpisodeSession(ABC, Generic[RecordT]):
    """One world and everything episodes share; ``run(k)`` gives episode k's record."""

    phases: tuple[str, ...] = ()  # the kind's phase names, in order: a dataset's per-frame labels
    # True: every episode after the first runs in a newly built world (built and prepared as for the
    # first), not in the restored snapshot. For kinds whose episodes are not yet the same after a
    # restore: Bullet's overlapping-pair order follows the bodies removed and re-added before, which
    # moves objects standing close together by micrometres (clear_table). Costs one build per episode.
    fresh_world_per_episode: bool = False
    # True: the kind's episodes take pictures of the world themselves (grasp perception's depth
    # camera), so its robots always load their visual meshes (see :meth:`draws`).
    takes_pictures: bool = False

    def __init__(self, task: CheckedTask, options: RunOptions, timing: BatchTiming | None = None):
        self.task, self.options = task, options
        self.seed = options.resolved_seed(task.config.sim.seed)
        self.timing = timing if timing is not None else BatchTiming()
        self._spawned: list[str] = []
        self._tap: EpisodeTap | None = None
        self._used = False  # an episode (or a replay) ran in the current world
        self._build_world()

    def _build_world(self) -> None:
        from robocfg.sim.world import World

        self.world: World = World(self.task, gui=self.options.gui, visuals=self.draws(),
                                  time_physics=self.options.time_physics)
        try:
            self.world.step(1)
            self.prepare()
            self._state = self.world.snapshot()
        except BaseException:
            self.world.close()
            raise
        collector.resume()  # the process's start is over (robocfg.collector; nothing unless it paused)

    def draws(self) -> bool:
        """Whether anything draws this session's world, so its robots need their visual meshes:
        the GUI, a picture recording (``record`` or a custom ``recorder``), a dataset sink when the
        task declares cameras, or a kind that ``takes_pictures``. Otherwise the world loads without
        them (the same physics; :class:`~robocfg.sim.world.World`'s ``visuals``)."""
        o = self.options
        return (o.gui or o.record is not None or o.recorder is not None or self.takes_pictures
                or (o.sink is not None and bool(self.task.config.cameras)))

    # ---- what a kind provides --------------------------------------------------------------
    def prepare(self) -> None:
        """Set up what every episode shares, before the snapshot (default: nothing)."""

    @abstractmethod
    def episode(self, k: int, recorder: FrameRecorder | None) -> RecordT:
        """Run episode ``k`` in the freshly restored world; return its record. A phase that fails
        ends the episode as a failed record (not an exception)."""

    @abstractmethod
    def report(self, records: list[RecordT], interrupted: bool) -> Any:
        """The run's report from the records of the episodes that finished."""

    def scene(self, k: int) -> ReplayScene:
        """Set up episode ``k`` in the freshly restored world up to where its recording begins
        (what ``episode`` does before calling :meth:`record_from`), for a replay."""
        from robocfg.errors import RobocfgError

        raise RobocfgError(f"'{self.task.config.task}' episodes cannot be replayed")

    def make_recorder(self, path: Any) -> FrameRecorder:
        """The picture recorder for ``--record PATH`` (default: the fitted scene camera)."""
        from robocfg.sim.record import Recorder

        # 10 fps: a frame costs ≈ 6 ms, 58 of them for a 5.8 s pick-place
        return Recorder(self.world, path, settings=self.options.recording)

    # ---- the engine ------------------------------------------------------------------------
    def rng(self, k: int) -> np.random.Generator:
        return episode_rng(self.seed, k)

    def log_for(self, k: int) -> Callable[[str], None]:
        """Episode ``k``'s log: the run's for episode 0, else :func:`silent` (an episode can tell
        that nothing reads its lines and skip formatting them)."""
        log = self.options.log if k == 0 else None
        return log or silent

    def spawn(self, body: Body, static: bool = False) -> int:
        """Add a body for this episode only (removed before the next episode's restore)."""
        self.remove_after_episode(body.name)
        return self.world.add_body(body, static=static)

    def remove_after_episode(self, name: str) -> None:
        """Remove body ``name`` (spawned by this episode) before the next episode's restore."""
        self._spawned.append(name)

    def record_from(self, arm: ArmHandle, obj: EpisodeObjects, phase_of: Callable[[], str],
                    language: Callable[[], str] | None = None) -> None:
        """With a dataset sink, record this episode from now on (call it once the episode's world
        is ready, before the first command): ``arm`` acts, ``obj`` is the episode's object body, or
        several objects' (name → body id, recorded side by side in that order), None: none;
        ``phase_of()`` names the current phase (one of ``phases``), ``language()``: the episode's
        instruction (None: the sink's). Without a sink: nothing (``language`` is not called). The
        engine ends the recording."""
        sink = self.options.sink
        if sink is not None and self._tap is None:
            self._tap = sink.begin(self.world, arm, obj, phase_of, self.phases, language() if language else "")

    def _reset(self) -> None:
        """Remove what the last episode spawned and restore the snapshot (or, with
        ``fresh_world_per_episode``, build a new world once one has been used)."""
        if self.fresh_world_per_episode and self._used:
            physics = self.world.physics_seconds
            self.world.close()
            self._spawned.clear()
            self._build_world()
            self.world.physics_seconds = physics  # the batch's physics time carries on
        self._used = True
        w = self.world
        for name in self._spawned:
            if name in w.bodies:
                w.remove_body(name)
        self._spawned.clear()
        w.restore(self._state)

    def replay_scene(self, k: int) -> ReplayScene:
        """Episode ``k``'s world, restored and set up as when its recording began (see ``scene``)."""
        self._reset()
        return self.scene(k)

    def run(self, k: int) -> RecordT:
        """Run episode ``k`` (any order, any number of times: the same record for the same k)."""
        t0 = time.perf_counter()  # a fresh world's build counts in the episode's wall time
        self._reset()
        w = self.world
        physics0 = w.physics_seconds
        recorder = self._recorder(k)
        self._tap = None
        try:
            record = self.episode(k, recorder)
        finally:
            tap, self._tap = self._tap, None
            if tap is not None:
                tap.stop()
        if tap is not None and self.options.sink is not None:
            self.options.sink.end(tap, k, self.seed + k, record.success, record.failed_phase, record.reason)
        if recorder is not None:
            ok = record.success  # the outcome banner of the last frame
            recorder.finish(ok, "" if ok else f"{record.failed_phase}: {record.reason}")
            recorder.save()
        self.timing.per_episode.append(time.perf_counter() - t0)
        self.timing.physics_per_episode.append(w.physics_seconds - physics0)
        return record

    def _recorder(self, k: int) -> FrameRecorder | None:
        o = self.options
        if k != o.record_episode:
            return None
        if o.recorder is not None:
            return o.recorder(self.world)
        return self.make_recorder(o.record) if o.record is not None else None

    def close(self) -> None:
        self.world.close()

    def __enter__(self) -> EpisodeSession[RecordT]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def run_batch(session: EpisodeSession[RecordT], options: RunOptions) -> tuple[list[RecordT], bool]:
    """Episodes 0 .. ``options.episodes`` − 1 in order; before each, ``should_stop`` may end the
    batch (then the second value, ``interrupted``, is True). ``on_episode`` sees every record run.
    Episodes in ``options.resumed`` (records of an interrupted run) are not run again: their records
    take their places in the returned list (index order), stopped or not."""
    done = resumed_by_index(options)
    records: list[RecordT] = []
    for k in range(options.episodes):
        if k in done:
            records.append(done[k])
            continue
        if options.stop_requested():
            return records + [done[j] for j in sorted(done) if j > k], True
        record = session.run(k)
        records.append(record)
        if options.on_episode is not None:
            options.on_episode(record)
    return records, False


def resumed_by_index(options: RunOptions) -> dict[int, Any]:
    """``options.resumed`` by episode index (``ValueError`` on an index run twice or out of range)."""
    done: dict[int, Any] = {}
    for r in options.resumed:
        k = int(r.index)
        if k in done or not 0 <= k < options.episodes:
            raise ValueError(f"resumed episode {k}: {'given twice' if k in done else 'not in 0..' + str(options.episodes - 1)}")
        done[k] = r
    return done


class SingleRunSession:
    """The session of a kind that runs one episode (gripper, trajectory, follow-target): episode
    0 is the whole run and its record is the run's report."""

    def __init__(self, runner: TaskRunner):
        self.runner = runner

    def run(self, k: int) -> Any:
        if k != 0:
            raise ValueError(f"'{self.runner.kind}' runs one episode: index {k} does not exist")
        return self.runner.run().report

    def close(self) -> None:
        pass

    def __enter__(self) -> SingleRunSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class EpisodicRunner(TaskRunner):
    """A kind whose run is a batch of seeded episodes in one session."""

    episodic = True

    @abstractmethod
    def open_session(self) -> EpisodeSession:
        """Build the world and what episodes share (the caller closes it)."""

    @contextmanager
    def replay_scene(self, k: int) -> Iterator[ReplayScene]:
        with self.open_session() as session:
            yield session.replay_scene(k)

    def run(self) -> RunOutput:
        t0 = time.perf_counter()
        with self.open_session() as session:
            records, interrupted = run_batch(session, self.options)
            report = session.report(records, interrupted)
        session.timing.wall_time = time.perf_counter() - t0
        return RunOutput(report, session.timing)
