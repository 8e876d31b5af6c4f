"""Build the controller's inputs from config: the arm (limits, TCP, mount) and the environment shapes.

Frames: world, 4×4 transforms, metres. Pure numpy + config (no PyBullet; a world is only asked
where its mesh bodies are).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.collision import EnvShape, robot_geometry
from robocfg.collision.bodies import body_env_shape
from robocfg.config.commands import FollowObstacle
from robocfg.config.scene import Body, Scene
from robocfg.config.types import AXIS_INDEX
from robocfg.geometry import pose_matrix
from robocfg.motion.reactive.controller import ArmSpec

if TYPE_CHECKING:
    from robocfg.checks.robot import CheckedRobot
    from robocfg.sim.world import World

DEFAULT_VELOCITY = 2.0  # rad/s for joints whose URDF gives no velocity limit


def velocity_limits(robot: CheckedRobot, arm: str | None = None) -> np.ndarray:
    """Joint velocity limits (rad/s, arm-joint order): the robot YAML's ``drives.velocity_limits``,
    else the URDF's, else ``DEFAULT_VELOCITY``."""
    names = robot.arm_joints(robot.config.arm(arm))
    limits = robot.config.drives.velocity_limits
    return np.array([limits.get(n) or robot.urdf.joints[n].velocity or DEFAULT_VELOCITY for n in names])


def arm_spec(robot: CheckedRobot, urdf_path: Path, base_pose: np.ndarray, arm: str | None = None,
             acceleration: float = 10.0, velocity_scale: float = 1.0,
             other_joints: dict[str, float] | None = None) -> ArmSpec:
    """``ArmSpec`` for ``arm`` of a ``CheckedRobot``: URDF limits (``drives`` overrides; continuous
    joints unbounded), TCP from
    ``tcp_offset``/``ee_axis``, posture = home; non-arm joints held at ``other_joints`` (default:
    as the kinematic model holds them, ``locked_joint_values``: the robot's ``locked_joints`` (a
    torso lift), other arms at home, grippers open, mimic followers following)."""
    from robocfg.kinematics.model import locked_joint_values

    cfg = robot.config
    arm_cfg = cfg.arm(arm)
    names = robot.arm_joints(arm_cfg)
    urdf = robot.urdf
    vel = velocity_limits(robot, arm_cfg.name)
    acc = np.array([cfg.drives.acceleration_limits.get(n, acceleration) for n in names])
    T_ee_tcp = np.eye(4)
    T_ee_tcp[AXIS_INDEX[arm_cfg.ee_axis], 3] = arm_cfg.tcp_offset
    held = dict(other_joints) if other_joints is not None else locked_joint_values(robot, arm_cfg.name, {})
    held = {j: v for j, v in held.items() if j not in names and j in urdf.joints}
    collision, _ = robot_geometry(robot)
    return ArmSpec(
        urdf_path=Path(urdf_path), joint_names=names, ee_link=arm_cfg.ee_link, T_ee_tcp=T_ee_tcp,
        base_pose=np.asarray(base_pose, float),
        lower=np.array([-np.inf if urdf.joints[n].type == "continuous" else urdf.joints[n].lower for n in names]),
        upper=np.array([np.inf if urdf.joints[n].type == "continuous" else urdf.joints[n].upper for n in names]),
        velocity_limits=vel * velocity_scale, acceleration_limits=acc,
        posture=np.asarray(arm_cfg.home, float), other_joints=held, collision=collision,
        tool_axis=AXIS_INDEX[arm_cfg.ee_axis],
    )


def body_shape(body: Body | FollowObstacle, obstacle: bool = True) -> EnvShape | None:
    """EnvShape of a primitive scene body (None for meshes: they are not modelled)."""
    if body.shape == "mesh":
        return None
    return EnvShape(body.name, body.shape, tuple(body.size), pose_matrix(body), obstacle)


def scene_shapes(scene: Scene, meshes: MeshPoses | None = None) -> tuple[list[EnvShape], list[str]]:
    """(environment shapes, names of bodies left out) for the ground, table, pedestal, obstacles and
    fixture parts. A mesh or URDF obstacle is the convex hull of its collision geometry
    (:func:`robocfg.collision.bodies.body_env_shape`, as the planner and the clutter filter see
    it) where ``meshes`` puts it; without ``meshes`` it is left out (named in the second list).
    Movable ``objects`` are not avoided (the robot may touch them)."""
    shapes: list[EnvShape] = []
    skipped: list[str] = []
    if scene.ground:
        shapes.append(EnvShape("ground", "halfspace", (), np.eye(4), obstacle=False))
    if scene.table is not None:
        T = pose_matrix(scene.table)
        T[:3, 3] -= T[:3, 2] * scene.table.size[2] / 2  # position is the top surface's centre
        shapes.append(EnvShape("table", "box", tuple(scene.table.size), T, obstacle=False))
    if scene.pedestal is not None:
        T = pose_matrix(scene.pedestal)
        T[:3, 3] -= T[:3, 2] * scene.pedestal.height / 2
        shapes.append(EnvShape("pedestal", "cylinder", (scene.pedestal.radius, scene.pedestal.height), T, obstacle=False))
    for ob in [*scene.obstacles, *scene.fixture_parts()]:
        s = body_shape(ob)
        if s is None and meshes is not None:
            s = body_env_shape(ob, meshes.pose(ob), meshes.base_dir)
        if s is None:
            skipped.append(ob.name)
        else:
            shapes.append(s)
    return shapes, skipped


class MeshPoses:
    """Where mesh bodies are for :func:`scene_shapes`: ``pose(body)`` (4×4, world) of the body frame
    the convex hull's vertices are given in (the frame PyBullet reports, ``World.body_pose``: for
    a URDF its root link's inertial frame); ``base_dir`` resolves relative mesh paths (the task
    file's folder)."""

    def __init__(self, base_dir: Path, pose: Callable[[Body], np.ndarray]):
        self.base_dir, self.pose = Path(base_dir), pose

    @classmethod
    def of(cls, world: World) -> MeshPoses:
        """Mesh bodies where ``world`` has them (as written in the task when not spawned)."""
        from robocfg.geometry import pose_to_matrix

        def pose(body: Body) -> np.ndarray:
            if body.name in world.bodies:
                return pose_to_matrix(*world.body_pose(body.name))
            return pose_matrix(body)

        return cls(world.task.path.parent, pose)
