"""``RobotEnv``: a Gymnasium environment around a robocfg ``World`` for any robot YAML.

Conventions follow panda-gym so goal-conditioned RL code works unchanged: observations are a
``Dict`` of ``observation``, ``achieved_goal`` and ``desired_goal`` (float32, world frame, m);
``compute_reward(achieved, desired, info)`` is vectorised for hindsight relabelling (HER).

Actions (``control="ee"``, the default): ``[dx, dy, dz]`` in [−1, 1] scaled by ``ee_step`` m and
added to the current TCP position; the orientation stays top-down (approach straight down, the
robot's ``R_ee_graspnet`` giving the wrist), and our IK (``KinematicModel``, LM backend with a
fixed iteration budget, so runs are reproducible) turns the pose into joint targets for the arm
drives. ``control="joints"``: one value per arm joint, scaled by ``joint_step`` rad (or m).
Tasks that use the gripper add one last action: > 0 opens, < 0 closes (a parallel gripper takes
the opening fraction ``(a + 1) / 2``; a suction cup switches on below zero).

The workspace lies on the ground just beyond the robot's home TCP, so goals suit robots of any size;
for an arm that cannot reach the ground (``dual_arm_lift``) the built-in pick_place task's
placement resolution gives a stand, as ``run pick-place`` does (``robocfg.motion.placement``), and
the workspace is its top (``Workspace.floor``). Each
``step`` advances ``step_time`` s of simulated time (0.04 s, panda-gym's default). ``reset``
restores a physics snapshot taken once after building, so resets are cheap; ``reset(seed=…)``
makes the episode reproducible.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from robocfg import api
from robocfg.config.task import PickPlaceTask
from robocfg.errors import RobocfgError
from robocfg.geometry import rotation_angle
from robocfg.kinematics.frames import top_down_grasps
from robocfg.sim.gripper import ParallelGripper

Control = Literal["ee", "joints"]
RewardType = Literal["sparse", "dense"]


@dataclass(frozen=True)
class Workspace:
    """Axis-aligned region (world m) where goals and objects are sampled, on the ground just
    beyond the robot's home TCP; ``lo``/``hi`` bound the TCP targets."""

    center: np.ndarray  # (3,) point of the floor a half-width beyond the home TCP, away from the base
    half: float  # m, half side of the sampling square
    lo: np.ndarray  # (3,) lowest TCP target
    hi: np.ndarray  # (3,) highest TCP target

    @property
    def floor(self) -> float:
        """Height (m) of the surface objects rest on: the ground, or the top of the placement stand."""
        return float(self.center[2])

    def sample_xy(self, rng: np.random.Generator) -> np.ndarray:
        return self.center[:2] + rng.uniform(-self.half, self.half, size=2)


class RobotEnv(gym.Env):
    """Base class: world, IK, action handling, goal observation. Subclasses (``tasks.py``) say
    what the goal is, what is observed besides the TCP, and what counts as success."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}  # noqa: RUF012  (gymnasium's own instance attribute)
    uses_gripper = False
    uses_object = False

    def __init__(self, robot: str = "panda", control: Control = "ee", reward_type: RewardType = "sparse",
                 render_mode: str | None = None, step_time: float = 0.04, distance_threshold: float = 0.05,
                 ee_step: float = 0.05, joint_step: float = 0.05, render_size: tuple[int, int] = (320, 240)):
        if control not in ("ee", "joints"):
            raise ValueError(f"control must be 'ee' or 'joints', got {control!r}")
        if reward_type not in ("sparse", "dense"):
            raise ValueError(f"reward_type must be 'sparse' or 'dense', got {reward_type!r}")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.control, self.reward_type, self.render_mode = control, reward_type, render_mode
        self.distance_threshold, self.ee_step, self.joint_step = distance_threshold, ee_step, joint_step
        self.render_size = render_size
        task = api.load_task("pick_place", robot=robot)
        # the placement `run pick-place` resolves (on the task as loaded: it knows the robot the file
        # was written for): a stand under the work area for an arm that cannot reach the floor (the
        # spots themselves are the env's own, sampled below)
        from robocfg.motion.placement import resolve_placement, with_stand

        stand = resolve_placement(task).stand
        # physics step: the task's, shortened so that a whole number of them make ``step_time``
        self.substeps = max(1, int(np.ceil(step_time / task.config.sim.timestep - 1e-9)))
        task = with_stand(task.with_overrides({"sim.timestep": step_time / self.substeps}), stand)
        self.world = api.make_world(task)
        self.arm = self.world.robot.arm()
        self.gripper = self.arm.gripper
        self.step_time = self.substeps * self.world.dt
        if not isinstance(task.config, PickPlaceTask):
            raise RobocfgError(f"the built-in pick_place task is of kind {task.config.task!r}")
        body = task.config.pick_place.object  # the task's cube: 5 cm, 0.1 kg
        self.object, self.object_half_height = body.name, body.size[2] / 2
        if self.uses_object:
            self.world.add_body(body)
        self.model = api.kinematic_model(task.robots[0], arm=self.arm.config.name,
                                         base_pose=self.world.robot.base_pose())
        self.model.solver("lm").max_total_iter = 60  # reproducible: bounded by iterations, not time
        home_tcp = self.arm.tcp_pose()
        self.R_down = self._top_down_rotation(home_tcp)
        out = home_tcp[:2, 3] - self.world.robot.base_pose()[:2, 3]  # base → home TCP, horizontal
        reach = float(np.linalg.norm(out))
        half = float(np.clip(0.3 * reach, 0.08, 0.15))
        if stand is None:  # centred a half-width beyond the home TCP: close to the base, top-down poses run out
            c = np.array([*(home_tcp[:2, 3] + half * out / max(reach, 1e-9)), 0.0])
        else:  # on the stand, objects whole on its top wherever they are sampled
            sx, sy, sz = stand.size  # a block fixture's position: its footprint centre, at its bottom
            c = np.array([stand.position[0], stand.position[1], stand.position[2] + sz])
            half = min(half, max(0.0, min(sx, sy) / 2 - max(body.size[:2])))
        self.workspace = Workspace(c, half, c + np.array([-2 * half, -2 * half, 0.0]),
                                   c + np.array([2 * half, 2 * half, max(0.3, 0.8 * (home_tcp[2, 3] - c[2]))]))
        self.world.step(1)
        self._state = self.world.snapshot()
        self.goal = np.zeros(3)
        self._prev_tcp = self._tcp = home_tcp[:3, 3].copy()
        n_act = self.model.nq if control == "joints" else 3
        n_act += 1 if self.uses_gripper else 0
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_act,), dtype=np.float32)
        obs = self._observe()
        self.observation_space = spaces.Dict({
            k: spaces.Box(-np.inf, np.inf, shape=v.shape, dtype=np.float32) for k, v in obs.items()})
        self._renderer: Any = None

    # ---- what subclasses define ------------------------------------------------------------
    def _sample_goal(self) -> np.ndarray:
        raise NotImplementedError

    def _place_scene(self) -> None:
        """Put objects where this episode wants them (after the snapshot is restored)."""

    def _achieved(self) -> np.ndarray:
        return self._tcp

    def _task_observation(self) -> np.ndarray:
        return np.zeros(0)

    def _advance_goal(self) -> None:
        """Move the goal during an episode (follow-target); fixed by default."""

    # ---- Gymnasium API ---------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self.world.restore(self._state)
        self.steps = 0
        self._place_scene()
        self.goal = self._sample_goal()
        self._prev_tcp = self._tcp = self.tcp()
        self._target_q = self.arm.joint_positions()
        return self._observe(), self._info()

    def step(self, action):
        a = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)
        self._apply(a)
        self._prev_tcp = self._tcp  # TCP read at the last observation: nothing moved since
        self.world.step(self.substeps)
        self.steps += 1
        self._advance_goal()
        obs, info = self._observe(), self._info()
        reward = float(self.compute_reward(obs["achieved_goal"], obs["desired_goal"], info))
        return obs, reward, bool(info["is_success"]) and self._terminate_on_success(), False, info

    def compute_reward(self, achieved_goal, desired_goal, info) -> np.ndarray | float:
        """Sparse: −1 until within ``distance_threshold`` m, then 0. Dense: −distance (m).
        Works on one goal pair or on batches (last axis = xyz), for HER."""
        d = np.linalg.norm(np.asarray(achieved_goal) - np.asarray(desired_goal), axis=-1)
        if self.reward_type == "sparse":
            return -(d > self.distance_threshold).astype(np.float32)
        return (-d).astype(np.float32)

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            from robocfg.sim.record import Recorder
            from robocfg.sim.record_camera import CameraView

            c = self.workspace.center
            cam = CameraView(target=(float(c[0]), float(c[1]), float(c[2]) + 0.15), distance=1.0 + 4 * self.workspace.half)
            self._renderer = Recorder(self.world, "frame.png", size=self.render_size, camera=cam)
        return self._renderer.render()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
        self.world.close()

    # ---- helpers ---------------------------------------------------------------------------
    def _terminate_on_success(self) -> bool:
        return True

    def tcp(self) -> np.ndarray:
        """TCP position (world, m)."""
        return self.arm.tcp_pose()[:3, 3].copy()

    def _observe(self) -> dict[str, np.ndarray]:
        tcp = self._tcp = self.tcp()  # read once per step (observation, goal, next action)
        vel = (tcp - self._prev_tcp) / self.step_time if hasattr(self, "steps") else np.zeros(3)
        parts = [tcp, vel]
        if self.uses_gripper:
            parts.append([self.gripper_opening()])
        parts.append(self._task_observation())
        return {"observation": np.concatenate(parts).astype(np.float32),
                "achieved_goal": self._achieved().astype(np.float32),
                "desired_goal": np.asarray(self.goal, dtype=np.float32)}

    def _info(self) -> dict[str, Any]:
        d = float(np.linalg.norm(self._achieved() - self.goal))
        return {"is_success": d <= self.distance_threshold, "distance": d}

    def gripper_opening(self) -> float:
        """Measured opening fraction (0 closed, 1 open; a suction cup: 0 while on); 1 without a gripper."""
        return 1.0 if self.gripper is None else float(self.gripper.fraction())

    def _apply(self, a: np.ndarray) -> None:
        if self.control == "ee":
            target = np.clip(self._tcp + self.ee_step * a[:3], self.workspace.lo, self.workspace.hi)
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = self.R_down, target
            res = self.model.ik(T, seed_q=self.arm.joint_positions(), backend="lm", time_budget=1.0,
                                rng=np.random.default_rng(0))
            # a partial answer still helps when it gets closer than where the TCP is now
            if res.converged or (res.pos_err < float(np.linalg.norm(target - self._tcp)) and res.rot_err < 0.2):
                self._target_q = res.q
        else:
            n = self.model.nq
            self._target_q = np.clip(self.arm.joint_positions() + self.joint_step * a[:n],
                                     self.model.lower, self.model.upper)
        self.arm.command(self._target_q)
        if self.uses_gripper:
            self._command_gripper(float(a[-1]))

    def _command_gripper(self, g: float) -> None:
        if self.gripper is None:
            return
        if isinstance(self.gripper, ParallelGripper):
            self.gripper.set_fraction((g + 1.0) / 2.0)
        elif g < 0:
            self.gripper.close()
        else:
            self.gripper.open()

    def _top_down_rotation(self, home_tcp: np.ndarray) -> np.ndarray:
        """World rotation of ``ee_link`` for a top-down grasp, the one of the two closest to home."""
        R_ee_g = np.asarray(self.arm.config.R_ee_graspnet, float)
        cands = [g.rotation @ R_ee_g for g in top_down_grasps(home_tcp[:3, 3], 0.0, (0.05, 0.05))]
        return min(cands, key=lambda R: rotation_angle(home_tcp[:3, :3], R))
