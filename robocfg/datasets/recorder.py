"""Sample observations and actions of one episode at the dataset rate, through the command gate.

``EpisodeRecorder.start()`` right after the episode's world is set up (frame 0) hooks ``on_step``
into the world's steps (``World.step_hooks``: whatever code steps the world is sampled);
``finish(...)`` at the end unhooks it. The engine drives both (``EpisodeSession.record_from``,
:mod:`robocfg.engine.dataset`); runners never call them. A frame only reads the simulator
(plain tuples, appended); arrays are built once, at the end of the episode.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from robocfg.config.types import AXIS_INDEX
from robocfg.datasets.episode import DatasetLayout, EpisodeRecord
from robocfg.datasets.gate import CommandGate
from robocfg.engine.dataset import EpisodeObjects, object_keys
from robocfg.errors import RobocfgError


def steps_per_frame(dt: float, fps: float) -> int:
    """Physics steps per dataset frame; the dataset rate must divide the physics rate. At the
    default 20 Hz a frame falls on every divergence check (``World.check_every``, 50 ms), after it;
    at other rates a frame off that grid is checked itself (``EpisodeRecorder._frame``)."""
    n = round(1.0 / (fps * dt))
    if n < 1 or abs(n * dt * fps - 1.0) > 1e-6:
        raise RobocfgError(f"--dataset-fps {fps:g} does not divide the physics rate {1 / dt:g} Hz; "
                           f"choose a divisor (e.g. {1 / (dt * max(1, n)):g})")
    return n


def layout_names(arm, objects: tuple[str, ...] = ("object",)) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """(state, env_state, action) entry names for ``arm`` (see :mod:`robocfg.datasets.episode`);
    ``objects``: the recorded objects' feature prefixes (``object``, or ``object.<name>`` each; none:
    no env_state entries)."""
    grip = tuple(arm.robot.checked.gripper_joints(arm.config)) if arm.gripper is not None else ()
    joints = tuple(arm.joints) + grip
    state = (*(f"{j}.pos" for j in joints), *(f"{j}.vel" for j in joints),
             *(f"tcp.{k}" for k in ("x", "y", "z", "qx", "qy", "qz", "qw")), "gripper.opening")
    env = tuple(f"{o}.{k}" for o in objects for k in ("x", "y", "z", "qx", "qy", "qz", "qw"))
    action = (*(f"{j}.target" for j in arm.joints), "gripper.command")
    return state, env, action


class EpisodeRecorder:
    """Frames of one episode of ``world`` (``arm`` acting, ``obj`` the object's body id, or several
    objects' (name → id), None: no object); ``language``: the episode's instruction ("": the sink's)."""

    def __init__(self, world, arm, obj: EpisodeObjects, layout: DatasetLayout, rig, phase_of: Callable[[], str],
                 replay_actions: np.ndarray | None = None, language: str = "",
                 tcp_fk: Callable[[np.ndarray], np.ndarray] | None = None):
        self.world, self.arm, self.layout, self.rig = world, arm, layout, rig
        self.objs = [bid for _, bid in object_keys(obj)]  # body ids, in the env_state's order
        self.phase_of, self.language = phase_of, language
        self.tcp_fk = tcp_fk  # arm joint values -> base_T_tcp (4x4), for EE-delta actions
        self.n = steps_per_frame(world.dt, layout.fps)
        self.gate = CommandGate(world, arm, self.n)
        self.replay_actions = replay_actions
        grip = list(arm.robot.checked.gripper_joints(arm.config)) if arm.gripper is not None else []
        self._joint_names = list(arm.joints) + grip
        # where each recorded joint sits among the robot's movable joints (the divergence check's
        # read, reused by a frame at the check's step); None: a recorded joint is not among them
        movable = arm.robot.movable_joints
        self._in_check = [movable.index(n) for n in self._joint_names] if set(self._joint_names) <= set(movable) else None
        self._base_inv = np.linalg.inv(world.robot.base_pose())
        self._phase_index = {p: i for i, p in enumerate(layout.phases)}
        self._hooked = False
        # per frame, as the simulator gives them (converted to arrays in ``finish``)
        self.q: list[list[float]] = []  # joint positions (arm then gripper joints)
        self.qd: list[list[float]] = []  # their velocities
        self.opening: list[float] = []
        self.ee: list[tuple[tuple[float, ...], tuple[float, ...]]] = []  # ee_link world (position, quat x y z w)
        self.obj_pose: list[tuple[tuple[float, ...], tuple[float, ...]]] = []  # objects' world (position, quat), frame-major
        self.actions: list[np.ndarray] = []
        self.phases: list[int] = []
        self.images: dict[str, list[np.ndarray]] = {c.name: [] for c in layout.cameras}
        self.depth: dict[str, list[np.ndarray]] = {c.name: [] for c in layout.cameras if c.depth}

    @property
    def lag_steps(self) -> int:
        """Physics steps the command gate delays the runner's commands by: one frame."""
        return self.n

    def start(self) -> None:
        """Frame 0 now; from here every physics step of the world is sampled."""
        self.gate.install()
        self._frame(first=True)
        self.gate.drive(1)
        self.world.step_hooks.append(self.on_step)
        self.world.play_through = self.play
        self._hooked = True

    def play(self, arm, q_rows: list, qd_rows: list, after: Callable[[], None] | None) -> bool:
        """``World.play`` of ``arm`` while recording: the same commands and frames as per row,
        without the per-step calls (:func:`robocfg.sim.playback.play_latched`); False where it does
        not apply (another arm, or another step hook besides this recorder)."""
        from robocfg.sim.playback import play_latched

        if arm is not self.arm or self.world.step_hooks != [self.on_step]:
            return False
        return play_latched(self.world, arm, q_rows, self.gate, self.n, self._frame, after)

    def on_step(self) -> None:
        j = self.world.steps % self.n
        if j == 0:
            self._frame()
        self.gate.drive(j + 1)

    def stop(self) -> None:
        """Unhook from the world's steps and give the commands back (idempotent)."""
        if self._hooked:
            self.world.step_hooks.remove(self.on_step)
            if self.world.play_through == self.play:
                self.world.play_through = None
            self._hooked = False
        self.gate.remove()

    def _frame(self, first: bool = False) -> None:
        w = self.world
        if not first and w.steps % w.check_every:  # a rate off the check grid (not a divisor of 20 Hz):
            w.check()  # every frame shows a checked state (PhysicsDiverged before a NaN is recorded)
        k = len(self.actions)
        replay = self.replay_actions
        if replay is not None:  # past the recorded frames the last action holds
            a = self.gate.latch(replay[min(k, len(replay) - 1)], first=first)
        else:
            a = self.gate.latch(first=first)
        self.actions.append(a)
        r, arm = self.arm.robot, self.arm
        # On a check's step (every frame at 20 Hz, and every frame off the grid, checked above) the
        # joints were just read by the check: the same values, without two more state queries.
        where = self._in_check
        read = None if first or where is None else w.checked_joint_states(r)
        if read is None or where is None:
            q, qd = r.joint_states(self._joint_names)
            opening = arm.gripper.fraction() if arm.gripper is not None else 0.0
        else:
            states = [read[i] for i in where]
            q, qd = [s[0] for s in states], [s[1] for s in states]
            opening = arm.gripper.fraction_at(q[len(arm.joints):]) if arm.gripper is not None else 0.0
        self.q.append(q)
        self.qd.append(qd)
        self.opening.append(opening)
        self.ee.append(r.link_position_quat(arm.config.ee_link))
        for bid in self.objs:
            self.obj_pose.append(self.world.body_pose_tuple(bid))
        self.phases.append(self._phase_index.get(self.phase_of(), 0))
        if self.rig is not None and self.layout.cameras:
            for name, img in self.rig.render_all().items():
                self.images[name].append(img.rgb)
                if img.depth is not None:
                    self.depth[name].append(img.depth)

    @staticmethod
    def _poses(frames: list) -> np.ndarray:
        """(T, 7) position + quaternion x y z w from (position, quaternion) tuples."""
        return np.array([(*pos, *quat) for pos, quat in frames], dtype=float).reshape(-1, 7)

    def _in_base(self) -> tuple[np.ndarray, np.ndarray]:
        """(T, 7) TCP and (T, 7 per object) object poses in the robot base frame (position m,
        quaternion x y z w), converted for all frames at once."""
        Tb = self._base_inv
        T_off = np.eye(4)
        T_off[AXIS_INDEX[self.arm.config.ee_axis], 3] = self.arm.config.tcp_offset
        ee = self._poses(self.ee)
        T_ee = np.tile(np.eye(4), (len(ee), 1, 1))
        T_ee[:, :3, :3], T_ee[:, :3, 3] = Rotation.from_quat(ee[:, 3:]).as_matrix(), ee[:, :3]
        T_tcp = Tb @ T_ee @ T_off
        tcp = np.concatenate([T_tcp[:, :3, 3], Rotation.from_matrix(T_tcp[:, :3, :3]).as_quat()], axis=1)
        if not self.objs:
            return tcp, np.zeros((len(tcp), 0))
        obj = self._poses(self.obj_pose)  # (T * objects, 7), frame-major
        pos = obj[:, :3] @ Tb[:3, :3].T + Tb[:3, 3]
        quat = (Rotation.from_matrix(Tb[:3, :3]) * Rotation.from_quat(obj[:, 3:])).as_quat()
        return tcp, np.concatenate([pos, quat], axis=1).reshape(len(tcp), 7 * len(self.objs))

    def final_pose(self) -> list[float]:
        """The objects' world poses now (position m, quaternion x y z w; 7 values per object, in
        order); with no object, the TCP's."""
        if self.objs:
            out: list[float] = []
            for bid in self.objs:
                pos, quat = self.world.body_pose_tuple(bid)
                out += [*map(float, pos), *map(float, quat)]
            return out
        from robocfg.geometry.pose import matrix_to_pose

        pos, quat = matrix_to_pose(self.arm.tcp_pose())
        return [*map(float, pos), *map(float, quat)]

    def finish(self, index: int, seed: int, language: str, success: bool, failed_phase: str | None,
               reason: str) -> EpisodeRecord:
        """The episode's record (the recorder is stopped)."""
        self.stop()
        action = np.asarray(self.actions, np.float32)
        ee_delta = ee_deltas(action, self.tcp_fk) if self.layout.ee_delta and self.tcp_fk is not None else None
        tcp, env = self._in_base()
        n = len(tcp)
        joints = np.concatenate([np.asarray(self.q, float).reshape(n, -1), np.asarray(self.qd, float).reshape(n, -1)],
                                axis=1)
        state = np.concatenate([joints, tcp, np.asarray(self.opening, float)[:, None]], axis=1)
        return EpisodeRecord(
            index=index, seed=seed, language=self.language or language, success=success, failed_phase=failed_phase,
            reason=reason, physics_steps=self.world.steps, object_final=self.final_pose(),
            state=state.astype(np.float32), env_state=env.astype(np.float32),
            action=action, phase=np.asarray(self.phases, np.int64), ee_delta=ee_delta,
            images={k: np.asarray(v, np.uint8) for k, v in self.images.items()},
            depth={k: np.asarray(v, np.float32) for k, v in self.depth.items()},
        )


def ee_deltas(action: np.ndarray, tcp_fk: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """(T, 7) float32 EE-delta actions of joint actions (T, arm joints + 1): the TCP pose change
    from action k − 1 to action k in the robot base frame (position m, rotation vector rad), then
    the gripper command; row 0 is zero motion (see :mod:`robocfg.datasets.episode`)."""
    T = np.array([tcp_fk(a[:-1].astype(np.float64)) for a in action]).reshape(-1, 4, 4)
    prev = np.concatenate([T[:1], T[:-1]])
    dp = T[:, :3, 3] - prev[:, :3, 3]
    rv = Rotation.from_matrix(T[:, :3, :3] @ np.transpose(prev[:, :3, :3], (0, 2, 1))).as_rotvec()
    return np.concatenate([dp, rv, action[:, -1:]], axis=1).astype(np.float32)
