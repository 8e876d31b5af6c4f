"""Play a run in the browser viewer: one episode is simulated headless first (by the engine, as
``robocfg run`` does), its joint states and body poses sampled every ``1 / fps`` s of simulated
time; the page then replays those samples (time slider, play/pause, phase). No simulation runs in
the page process while it is shown, and moving the slider back and forth costs nothing.

Units: s, m, rad; body poses are (position, quaternion x y z w) in the world frame.
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field

from robocfg.engine.options import EpisodeObserver
from robocfg.errors import RobocfgError

PLAYBACK_FPS = 30.0
STATIC_BODIES = ("ground", "table", "pedestal")  # never move: not sampled
BodyPose = tuple[tuple[float, float, float], tuple[float, float, float, float]]  # (position m, quat xyzw)


@dataclass(frozen=True)
class PlaybackFrame:
    """The world at time ``t``: joint positions of every robot (by joint name, one dict per robot
    in the task's order), the pose of every free body (by name), and the phase under way."""

    t: float
    phase: str
    joints: tuple[dict[str, float], ...]
    bodies: dict[str, BodyPose]


@dataclass
class Playback:
    """Sampled frames of one episode, its outcome (``success`` None until known) and the phases'
    start times."""

    frames: list[PlaybackFrame] = field(default_factory=list)
    success: bool | None = None
    reason: str = ""

    @property
    def duration(self) -> float:
        return self.frames[-1].t if self.frames else 0.0

    def at(self, t: float) -> PlaybackFrame:
        """The last frame taken at or before ``t`` (the first one before it starts)."""
        k = bisect_right([f.t for f in self.frames], t + 1e-9) - 1
        return self.frames[max(0, k)]

    def phases(self) -> list[tuple[str, float]]:
        """(phase, start time) in order."""
        out: list[tuple[str, float]] = []
        for f in self.frames:
            if not out or out[-1][0] != f.phase:
                out.append((f.phase, f.t))
        return out


class StateRecorder(EpisodeObserver):
    """The engine's episode recorder that samples states (not pictures) into a :class:`Playback`."""

    def __init__(self, world, fps: float = PLAYBACK_FPS):
        self.world, self.fps = world, fps
        self.playback = Playback()
        self.phase = ""
        self._next_t = 0.0

    def maybe_capture(self) -> None:
        if self.world.t + 1e-9 >= self._next_t:
            self.capture()
            self._next_t = self.world.t + 1.0 / self.fps

    def capture(self) -> None:
        w = self.world
        robots = {r.name for r in w.robots}
        joints = tuple({n: float(v) for n, v in zip(r.movable_joints, r.joint_positions(), strict=True)}
                       for r in w.robots)
        bodies: dict[str, BodyPose] = {}
        for name in list(w.bodies):
            if name in robots or name in STATIC_BODIES or name.startswith(("table_leg_", "_")):
                continue
            (x, y, z), (qx, qy, qz, qw) = w.body_pose(name)
            bodies[name] = ((float(x), float(y), float(z)), (float(qx), float(qy), float(qz), float(qw)))
        self.playback.frames.append(PlaybackFrame(float(w.t), self.phase, joints, bodies))

    def set_phase(self, name: str) -> None:
        self.phase = name

    def finish(self, success: bool, reason: str = "") -> None:
        self.playback.success, self.playback.reason = bool(success), reason

    def save(self) -> None:
        self.capture()  # the final state
        return None


def record_run(task, seed: int | None = None, episode: int = 0, fps: float = PLAYBACK_FPS) -> Playback:
    """Simulate episode ``episode`` of ``task`` (a checked task of an episodic kind: pick-place,
    grasp) headless and return its playback."""
    from robocfg.engine import RunOptions, run

    made: list[StateRecorder] = []

    def factory(world) -> StateRecorder:
        made.append(StateRecorder(world, fps))
        return made[-1]

    run(task, RunOptions(seed=seed, episodes=episode + 1, record_episode=episode, recorder=factory))
    if not made or not made[0].playback.frames:
        raise RobocfgError(f"a {task.config.task} run cannot be played back in the viewer "
                           "(only kinds that run episodes: pick_place, grasp)")
    return made[0].playback

