"""Sample observations and actions of one episode at the dataset rate, through the command gate.

``EpisodeRecorder.start()`` right after the episode's world is set up (frame 0), ``on_step()``
after every physics step, ``finish(...)`` at the end. The runner's only coupling is those three
calls (see :mod:`robocfg.datasets.pick_place`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from robocfg.datasets.episode import DatasetLayout, EpisodeRecord
from robocfg.datasets.gate import CommandGate
from robocfg.errors import RobocfgError


def steps_per_frame(dt: float, fps: float) -> int:
    """Physics steps per dataset frame; the dataset rate must divide the physics rate."""
    n = round(1.0 / (fps * dt))
    if n < 1 or abs(n * dt * fps - 1.0) > 1e-6:
        raise RobocfgError(f"--dataset-fps {fps:g} does not divide the physics rate {1 / dt:g} Hz; "
                           f"choose a divisor (e.g. {1 / (dt * max(1, n)):g})")
    return n


def layout_names(arm) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """(state, env_state, action) entry names for ``arm`` (see :mod:`robocfg.datasets.episode`)."""
    grip = tuple(arm.robot.checked.gripper_joints(arm.config)) if arm.gripper is not None else ()
    joints = tuple(arm.joints) + grip
    state = (*(f"{j}.pos" for j in joints), *(f"{j}.vel" for j in joints),
             *(f"tcp.{k}" for k in ("x", "y", "z", "qx", "qy", "qz", "qw")), "gripper.opening")
    env = tuple(f"object.{k}" for k in ("x", "y", "z", "qx", "qy", "qz", "qw"))
    action = (*(f"{j}.target" for j in arm.joints), "gripper.command")
    return state, env, action


class EpisodeRecorder:
    """Frames of one episode of ``world`` (``arm`` acting, ``obj`` the object's body id)."""

    def __init__(self, world, arm, obj: int, layout: DatasetLayout, rig, phase_of: Callable[[], str],
                 replay_actions: np.ndarray | None = None):
        self.world, self.arm, self.obj, self.layout, self.rig = world, arm, obj, layout, rig
        self.phase_of = phase_of
        self.n = steps_per_frame(world.dt, layout.fps)
        self.gate = CommandGate(world, arm, self.n)
        self.replay_actions = replay_actions
        self._grip_joints = list(arm.robot.checked.gripper_joints(arm.config)) if arm.gripper is not None else []
        self._base_inv = np.linalg.inv(world.robot.base_pose())
        self._phase_index = {p: i for i, p in enumerate(layout.phases)}
        self.state: list[np.ndarray] = []
        self.env: list[np.ndarray] = []
        self.actions: list[np.ndarray] = []
        self.phases: list[int] = []
        self.images: dict[str, list[np.ndarray]] = {c.name: [] for c in layout.cameras}
        self.depth: dict[str, list[np.ndarray]] = {c.name: [] for c in layout.cameras if c.depth}

    def start(self) -> None:
        self.gate.install()
        self._frame(first=True)
        self.gate.drive(1)

    def on_step(self) -> None:
        j = self.world.steps % self.n
        if j == 0:
            self._frame()
        self.gate.drive(j + 1)

    def stop(self) -> None:
        self.gate.remove()

    def _frame(self, first: bool = False) -> None:
        k = len(self.actions)
        replay = self.replay_actions
        if replay is not None:  # past the recorded frames the last action holds
            a = self.gate.latch(replay[min(k, len(replay) - 1)], first=first)
        else:
            a = self.gate.latch(first=first)
        self.actions.append(a)
        self.state.append(self._state())
        self.env.append(self._pose_in_base(*self.world.body_pose(self.obj)))
        self.phases.append(self._phase_index.get(self.phase_of(), 0))
        if self.rig is not None and self.layout.cameras:
            for name, img in self.rig.render_all().items():
                self.images[name].append(img.rgb)
                if img.depth is not None:
                    self.depth[name].append(img.depth)

    def _state(self) -> np.ndarray:
        r, arm = self.arm.robot, self.arm
        names = list(arm.joints) + self._grip_joints
        T = self._base_inv @ arm.tcp_pose()
        g = arm.gripper
        opening = g.width() if hasattr(g, "width") else (g.state() if g is not None else 0.0)
        return np.concatenate([r.joint_positions(names), r.joint_velocities(names), T[:3, 3],
                               Rotation.from_matrix(T[:3, :3]).as_quat(), [opening]])

    def _pose_in_base(self, pos, quat_xyzw) -> np.ndarray:
        R = self._base_inv[:3, :3]
        p = R @ np.asarray(pos) + self._base_inv[:3, 3]
        q = (Rotation.from_matrix(R) * Rotation.from_quat(quat_xyzw)).as_quat()
        return np.concatenate([p, q])

    def finish(self, index: int, seed: int, language: str, success: bool, failed_phase: str | None,
               reason: str) -> EpisodeRecord:
        """The episode's record (the gate is removed)."""
        self.stop()
        pos, quat = self.world.body_pose(self.obj)
        return EpisodeRecord(
            index=index, seed=seed, language=language, success=success, failed_phase=failed_phase,
            reason=reason, physics_steps=self.world.steps, object_final=[*map(float, pos), *map(float, quat)],
            state=np.asarray(self.state, np.float32), env_state=np.asarray(self.env, np.float32),
            action=np.asarray(self.actions, np.float32), phase=np.asarray(self.phases, np.int64),
            images={k: np.asarray(v, np.uint8) for k, v in self.images.items()},
            depth={k: np.asarray(v, np.float32) for k, v in self.depth.items()},
        )
