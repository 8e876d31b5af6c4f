"""The dataset sink the episode engine feeds: one :class:`EpisodeRecorder` per episode, kept
episodes to a writer (LeRobot v3.0 or robomimic HDF5). It implements
:class:`robocfg.engine.dataset.EpisodeSink`.

The engine calls ``recorder = sink.begin(world, arm, obj, phase_of, phases, language)`` once the
episode's world is ready (before its first command; the recorder then samples every physics
step by itself), and ``sink.end(recorder, index, seed, success, failed_phase, reason)`` when the
episode is over; ``sink.close()`` after the last one writes the metadata.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

from robocfg.datasets.episode import Actions, CameraLayout, DatasetLayout
from robocfg.datasets.files import FileLimits
from robocfg.datasets.recorder import EpisodeRecorder, layout_names
from robocfg.engine.dataset import EpisodeObjects, object_keys

if TYPE_CHECKING:
    from robocfg.sim.camera_rig import Renderer

Format = Literal["lerobot", "hdf5"]
Keep = Literal["success", "all"]


def make_writer(fmt: Format, root: Path, layout: DatasetLayout, extra_info: dict, limits: FileLimits | None = None):
    """The writer of ``fmt``; ``limits``: when a LeRobot dataset's files roll over (HDF5 is one file)."""
    if fmt == "lerobot":
        from robocfg.datasets.lerobot import LeRobotWriter

        return LeRobotWriter(root, layout, extra_info, limits)
    from robocfg.datasets.hdf5 import Hdf5Writer

    return Hdf5Writer(root, layout, extra_info)


@dataclass(frozen=True)
class DatasetSummary:
    """What a sink wrote: path, format, episodes kept of those run, frames."""

    path: str
    format: str
    episodes_kept: int
    episodes_run: int
    frames: int


@dataclass
class DatasetSink:
    """Records every episode of a run; ``keep="success"`` writes only successful ones.

    ``language``: the task string stored with every episode whose kind gives none; ``extra_info``:
    run facts stored in the dataset metadata (task path, arm, seed) that replay needs;
    ``renderer``: how camera images are drawn (``robocfg.sim.camera_rig``: auto, tiny, exact, egl);
    ``limits``: when a LeRobot dataset's data and video files roll over (lerobot's defaults).
    """

    root: Path
    fmt: Format
    task: Any  # a CheckedTask
    fps: int = 20
    keep: Keep = "success"
    language: str = ""
    extra_info: dict = field(default_factory=dict)
    renderer: Renderer = "auto"
    actions: Actions = "joint"  # --dataset-actions
    limits: FileLimits = field(default_factory=FileLimits)  # --dataset-data-mb, --dataset-video-mb, --dataset-chunk-files
    writer: Any = field(default=None, init=False)
    layout: DatasetLayout | None = field(default=None, init=False)
    run: int = field(default=0, init=False)
    kept: int = field(default=0, init=False)
    frames: int = field(default=0, init=False)
    kept_indices: list[int] = field(default_factory=list, init=False)  # run episode indices written, in order
    _rig: tuple | None = field(default=None, init=False)
    _fk: dict[str, Callable] = field(default_factory=dict, init=False)  # arm name -> base_T_tcp(q)

    def begin(self, world, arm, obj: EpisodeObjects, phase_of: Callable[[], str], phases: tuple[str, ...] = (),
              language: str = "") -> EpisodeRecorder:
        from robocfg.sim.camera_rig import CameraRig

        cams = self.task.config.cameras
        if self.layout is None:
            state, env, action = layout_names(arm, tuple(key for key, _ in object_keys(obj)))
            self.layout = DatasetLayout(
                fps=self.fps, robot=arm.robot.name, task_name=self.task.path.stem, state_names=state,
                env_state_names=env, action_names=action, phases=tuple(phases) or ("run",),
                cameras=tuple(CameraLayout(c.name, c.height, c.width, c.depth) for c in cams), actions=self.actions)
            self.writer = make_writer(self.fmt, Path(self.root), self.layout, self.extra_info, self.limits)
        if self._rig is None or self._rig[0] is not world:
            if self._rig is not None:
                self._rig[1].close()
            self._rig = (world, CameraRig(world, arm, cams, self.renderer))
        rec = EpisodeRecorder(world, arm, obj, self.layout, self._rig[1], phase_of, language=language,
                              tcp_fk=self._tcp_fk(arm) if self.layout.ee_delta else None)
        rec.start()
        return rec

    def _tcp_fk(self, arm) -> Callable:
        """base_T_tcp (4x4) of ``arm``'s joint values: a kinematic model with the base at the
        origin, built once per arm (other joints locked as the controllers lock them)."""
        if arm.config.name not in self._fk:
            from robocfg.kinematics.model import KinematicModel

            model = KinematicModel.from_robot(arm.robot.checked, arm.config.name)
            self._fk[arm.config.name] = model.fk
        return self._fk[arm.config.name]

    def end(self, rec: EpisodeRecorder, index: int, seed: int, success: bool, failed_phase: str | None,
            reason: str) -> None:
        ep = rec.finish(index, seed, self.language, success, failed_phase, reason)
        self.run += 1
        if success or self.keep == "all":
            self.writer.add(ep)
            self.kept += 1
            self.kept_indices.append(index)
            self.frames += ep.length

    def close(self) -> DatasetSummary:
        if self._rig is not None:
            self._rig[1].close()
            self._rig = None
        if self.writer is not None:
            self.writer.close()
        return DatasetSummary(str(self.root), self.fmt, self.kept, self.run, self.frames)
