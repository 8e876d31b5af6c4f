"""The engine's side of datasets: the options every recording kind offers, the sink protocol the
engine drives, and the scene a replay re-simulates.

Recording is generic: a kind only says *when* its episode's world is ready and *what* is acted on
(``EpisodeSession.record_from(arm, obj, phase_of)``, before its first command); the sink's tap
then samples the episode after every physics step (a ``World.step_hooks`` entry, whatever code
steps the world) and intercepts the arm and gripper commands (the command gate of
:mod:`robocfg.datasets.gate`); the engine ends it with the episode's record. Replay is the same
path the other way: the kind rebuilds episode k's world up to that point (``ReplayScene``) and the
recorded actions drive it through the same gate.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from robocfg.engine.options import option

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle
    from robocfg.sim.world import World

# What an episode is about: one object's body id, several objects (name → body id, in the task's
# order: their poses side by side in the environment state), or None (no object).
EpisodeObjects = int | Mapping[str, int] | None


def object_keys(obj: EpisodeObjects) -> tuple[tuple[str, int], ...]:
    """(feature prefix, body id) per recorded object, in order: ``object`` for one object,
    ``object.<name>`` for each of several, nothing for none."""
    if obj is None:
        return ()
    if isinstance(obj, int):
        return (("object", obj),)
    return tuple((f"object.{name}", int(bid)) for name, bid in obj.items())


@dataclass(frozen=True)
class DatasetOptions:
    """``--dataset*`` options of a kind that records datasets (subclass it for the kind's own
    ``Options``; the CLI builds the sink from these fields)."""

    dataset: Path | None = field(default=None, metadata=option(
        "--dataset", help="Record the episodes into this new directory (see --dataset-format)."))
    dataset_format: str = field(default="lerobot", metadata=option(
        "--dataset-format", choices=("lerobot", "hdf5"),
        help="lerobot (LeRobot v3.0: parquet + MP4) or hdf5 (robomimic layout)."))
    dataset_fps: int = field(default=20, metadata=option(
        "--dataset-fps", minimum=1, help="Frames per second of simulated time (must divide the physics rate)."))
    dataset_actions: str = field(default="joint", metadata=option(
        "--dataset-actions", choices=("joint", "ee_delta", "both"),
        help="joint: action = joint position targets + gripper; ee_delta: action = the commanded TCP pose change per "
             "frame (base frame: dx dy dz m, rotation vector rad) + gripper, the joint targets kept as action.joint; "
             "both: joint actions and action.ee_delta. Replay always uses the joint targets."))
    keep: str = field(default="success", metadata=option(
        "--keep", choices=("success", "all"), help="success: write successful episodes only; all: failures too, labelled."))
    dataset_renderer: str = field(default="auto", metadata=option(
        "--dataset-renderer", choices=("auto", "tiny", "exact", "egl"),
        help="Camera images: tiny (TinyRenderer on low-poly copies, CPU), egl (PyBullet's EGL plugin, GPU), "
             "auto (egl where an NVIDIA GPU is, else tiny) or exact (TinyRenderer on the full meshes; slowest)."))
    dataset_data_mb: float = field(default=100.0, metadata=option(
        "--dataset-data-mb", help="LeRobot: start a new data parquet file when the current one would reach this "
                                  "many MB (2**20 bytes) with the next episode (lerobot's data_files_size_in_mb)."))
    dataset_video_mb: float = field(default=200.0, metadata=option(
        "--dataset-video-mb", help="LeRobot: start a new video file (per camera) when the current one would reach "
                                   "this many MB with the next episode (lerobot's video_files_size_in_mb)."))
    dataset_chunk_files: int = field(default=1000, metadata=option(
        "--dataset-chunk-files", minimum=1, help="LeRobot: files per chunk-NNN directory, at most 1000 (lerobot's "
                                                 "chunks_size)."))


class EpisodeTap(Protocol):
    """One episode being recorded (``robocfg.datasets.recorder.EpisodeRecorder``): hooked into the
    world's steps from ``begin`` until ``stop``."""

    @property
    def lag_steps(self) -> int:
        """Physics steps by which the runner's commands reach the drives late while recorded
        (one dataset frame: the command gate). A runner that knows its future commands (a
        planned trajectory) can send them this much ahead."""
        ...

    def stop(self) -> None:
        """Unhook from the world and give the commands back to the runner (idempotent)."""


class EpisodeSink(Protocol):
    """Where recorded episodes go (``robocfg.datasets.sink.DatasetSink``; a worker's shard switch).

    ``begin``: the episode's world is ready — sample it from now on; ``arm`` acts, ``obj`` is the
    body id of the object the episode is about, or the objects' (name → id), None: no object
    (:data:`EpisodeObjects`); ``phase_of()`` names the
    current phase, one of ``phases``; ``language``: the episode's instruction ("" = the sink's).
    ``end``: the episode is over (the tap is stopped) with this outcome."""

    def begin(self, world: World, arm: ArmHandle, obj: EpisodeObjects, phase_of: Callable[[], str],
              phases: tuple[str, ...], language: str = "") -> EpisodeTap: ...

    def end(self, tap: EpisodeTap, index: int, seed: int, success: bool, failed_phase: str | None,
            reason: str) -> None: ...


@dataclass
class ReplayScene:
    """Episode k's world as its recording began: ``arm`` to drive, ``obj`` the episode's object(s)
    (:data:`EpisodeObjects`), ``judge()`` → (success, reason) of the outcome once the actions have played."""

    world: World
    arm: ArmHandle
    obj: EpisodeObjects
    judge: Callable[[], tuple[bool, str]]
