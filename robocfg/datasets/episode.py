"""What one recorded episode holds, and what every episode of a dataset shares (its layout).

Frames are taken every ``1 / fps`` s of simulated time, frame k at t = k / fps (frame 0 is the
state the episode starts in). Per frame:

* ``state`` (robot, base frame): arm joint positions (rad), gripper joint positions (rad or m),
  arm joint velocities, gripper joint velocities, TCP position (m) and orientation (quaternion
  x y z w) in the robot base frame, gripper opening (measured opening fraction of the driven
  finger joints, 0 = closed to 1 = open; a suction cup: 0 while on, 1 when off);
* ``env_state``: the object's position (m) and orientation (quaternion x y z w) in the robot base
  frame;
* ``action``: the arm joint position targets (rad) that the drives reach at frame k + 1 (the
  targets ramp linearly from action k - 1 to action k over the interval), then the gripper
  command (+1 open, -1 close) applied from frame k on — exactly what drove the robot;
* ``ee_delta`` (``--dataset-actions ee_delta|both``): the commanded TCP pose change of action k,
  in the robot base frame: T_k = FK(action k's joint targets), position change p_k − p_(k−1) (m),
  rotation change R_k R_(k−1)^T as a rotation vector (rad, base-frame axes), then the gripper
  command; frame 0 changes nothing (the gate's first ramp starts at action 0). Summed from frame 0
  they give the commanded TCP pose relative to action 0's;
* ``phase``: index into ``DatasetLayout.phases`` of the phase the runner was in;
* one RGB image (and optional depth, m) per task camera.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

Actions = Literal["joint", "ee_delta", "both"]
EE_DELTA_NAMES = ("tcp.dx", "tcp.dy", "tcp.dz", "tcp.drx", "tcp.dry", "tcp.drz", "gripper.command")


@dataclass(frozen=True)
class CameraLayout:
    """A camera's key and image size (pixels); ``depth``: a depth image is recorded too."""

    name: str
    height: int
    width: int
    depth: bool = False


@dataclass(frozen=True)
class DatasetLayout:
    """Names of every vector entry, the frame rate (Hz), phases and cameras shared by all episodes."""

    fps: int
    robot: str
    task_name: str
    state_names: tuple[str, ...]
    env_state_names: tuple[str, ...]
    action_names: tuple[str, ...]
    phases: tuple[str, ...] = ()  # the kind's phase names (EpisodeSession.phases)
    cameras: tuple[CameraLayout, ...] = ()
    actions: Actions = "joint"  # which actions are stored (--dataset-actions)

    @property
    def ee_delta(self) -> bool:
        """EE-delta actions are stored (as ``action``, or beside the joint ones)."""
        return self.actions != "joint"


@dataclass
class EpisodeRecord:
    """One episode: per-frame arrays (length T) and its outcome.

    ``physics_steps`` is how many physics steps the episode ran (replay runs the same number);
    ``object_final`` is the object's final world position (m) and quaternion x y z w.
    """

    index: int
    seed: int
    language: str
    success: bool
    failed_phase: str | None
    reason: str
    physics_steps: int
    object_final: list[float]
    state: np.ndarray  # (T, len(state_names)) float32
    env_state: np.ndarray  # (T, 7) float32
    action: np.ndarray  # (T, len(action_names)) float32
    phase: np.ndarray  # (T,) int64
    images: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (T, H, W, 3) uint8
    depth: dict[str, np.ndarray] = field(default_factory=dict)  # name -> (T, H, W) float32, m
    ee_delta: np.ndarray | None = None  # (T, 7) float32 (EE_DELTA_NAMES) when the layout stores them

    @property
    def length(self) -> int:
        return int(self.state.shape[0])
