"""Sample observations and actions of one episode at the dataset rate, through the command gate.

``EpisodeRecorder.start()`` right after the episode's world is set up (frame 0), ``on_step()``
after every physics step, ``finish(...)`` at the end. The runner's only coupling is those three
calls (see :mod:`robocfg.datasets.pick_place`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from robocfg.config.types import AXIS_INDEX
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
        grip = list(arm.robot.checked.gripper_joints(arm.config)) if arm.gripper is not None else []
        self._joint_names = list(arm.joints) + grip
        self._base_inv = np.linalg.inv(world.robot.base_pose())
        self._phase_index = {p: i for i, p in enumerate(layout.phases)}
        self.joints: list[np.ndarray] = []  # positions then velocities
        self.opening: list[float] = []
        self.T_ee: list[np.ndarray] = []  # ee_link world position + quaternion x y z w per frame
        self.obj_pose: list[np.ndarray] = []  # world position + quaternion x y z w per frame
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
        r, arm, names = self.arm.robot, self.arm, self._joint_names
        self.joints.append(np.concatenate([r.joint_positions(names), r.joint_velocities(names)]))
        self.opening.append(arm.gripper.fraction() if arm.gripper is not None else 0.0)
        pos, quat = r.link_position_quat(arm.config.ee_link)
        self.T_ee.append(np.concatenate([pos, quat]))
        self.obj_pose.append(np.concatenate(self.world.body_pose(self.obj)))
        self.phases.append(self._phase_index.get(self.phase_of(), 0))
        if self.rig is not None and self.layout.cameras:
            for name, img in self.rig.render_all().items():
                self.images[name].append(img.rgb)
                if img.depth is not None:
                    self.depth[name].append(img.depth)

    def _in_base(self) -> tuple[np.ndarray, np.ndarray]:
        """(T, 7) TCP and (T, 7) object poses in the robot base frame (position m, quaternion
        x y z w), converted for all frames at once."""
        Tb = self._base_inv
        T_off = np.eye(4)
        T_off[AXIS_INDEX[self.arm.config.ee_axis], 3] = self.arm.config.tcp_offset
        ee = np.asarray(self.T_ee).reshape(-1, 7)
        T_ee = np.tile(np.eye(4), (len(ee), 1, 1))
        T_ee[:, :3, :3], T_ee[:, :3, 3] = Rotation.from_quat(ee[:, 3:]).as_matrix(), ee[:, :3]
        T_tcp = Tb @ T_ee @ T_off
        tcp = np.concatenate([T_tcp[:, :3, 3], Rotation.from_matrix(T_tcp[:, :3, :3]).as_quat()], axis=1)
        obj = np.asarray(self.obj_pose).reshape(-1, 7)
        pos = obj[:, :3] @ Tb[:3, :3].T + Tb[:3, 3]
        quat = (Rotation.from_matrix(Tb[:3, :3]) * Rotation.from_quat(obj[:, 3:])).as_quat()
        return tcp, np.concatenate([pos, quat], axis=1)

    def finish(self, index: int, seed: int, language: str, success: bool, failed_phase: str | None,
               reason: str) -> EpisodeRecord:
        """The episode's record (the gate is removed)."""
        self.stop()
        pos, quat = self.world.body_pose(self.obj)
        tcp, env = self._in_base()
        state = np.concatenate([np.asarray(self.joints).reshape(len(tcp), -1), tcp,
                                np.asarray(self.opening)[:, None]], axis=1)
        return EpisodeRecord(
            index=index, seed=seed, language=language, success=success, failed_phase=failed_phase,
            reason=reason, physics_steps=self.world.steps, object_final=[*map(float, pos), *map(float, quat)],
            state=state.astype(np.float32), env_state=env.astype(np.float32),
            action=np.asarray(self.actions, np.float32), phase=np.asarray(self.phases, np.int64),
            images={k: np.asarray(v, np.uint8) for k, v in self.images.items()},
            depth={k: np.asarray(v, np.float32) for k, v in self.depth.items()},
        )
