"""One robot on the browser viewer's page (viser): its URDF meshes at a mount, its joint values,
and the drawing of its frames (base, ``ee_link``, TCP, grasp triads; ``ee_axis``; finger pads).

Poses are 4x4 world transforms (m); viser takes quaternions as (w, x, y, z).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import partial
from typing import TYPE_CHECKING, Literal, TypeVar

import numpy as np

from robocfg.checks import CheckedRobot
from robocfg.config.robot import ParallelGripperConfig
from robocfg.geometry.rotation import matrix_to_quat
from robocfg.viewer.frames import BOX_EDGES, ArmFrames

if TYPE_CHECKING:
    import viser
    import yourdfpy
    from viser.extras import ViserUrdf

Anchor = Literal["bottom-left", "top-left", "bottom-right", "top-right"]
LABEL_ANCHORS: tuple[Anchor, ...] = ("bottom-left", "top-left", "bottom-right", "top-right")  # base, ee_link, TCP, grasp: apart
V = TypeVar("V", int, float, bool)


def wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    """viser's (w, x, y, z) quaternion of a rotation matrix."""
    x, y, z, w = matrix_to_quat(R)
    return (float(w), float(x), float(y), float(z))


def set_value(handle: viser.GuiInputHandle[V], value: V) -> None:
    """Set a GUI input's value (its update handlers run, as when the user moves it)."""
    # viser declares the ``value`` setter apart from its getter, so type checkers see the property
    # as read-only; the setter exists and is what viser documents for moving an input.
    handle.value = value  # type: ignore[misc]


@dataclass
class ShownRobot:
    """One robot on the page: its config, mount (4x4 world_T_root), URDF (yourdfpy) and joints."""

    checked: CheckedRobot
    mount: np.ndarray
    node: str
    urdf: yourdfpy.URDF
    shown: ViserUrdf
    q: dict[str, float] = field(default_factory=dict)  # actuated joint → value (rad or m)

    def link_pose(self, link: str) -> np.ndarray:
        """World pose (4x4) of ``link`` at the joint values last sent with :meth:`apply`."""
        return self.mount @ self.urdf.get_transform(link, self.urdf.base_link)

    def apply(self) -> None:
        """Send the joint values ``q`` to the page (joints not in ``q`` at 0)."""
        names = self.urdf.actuated_joint_names
        self.shown.update_cfg(np.array([self.q.get(n, 0.0) for n in names]))


def add_robot(server: viser.ViserServer, robot: CheckedRobot, mount: np.ndarray, node: str,
              q0: list[float] | None) -> ShownRobot:
    """Put ``robot`` on the page under ``node`` at ``mount``, every arm at ``q0`` (the first arm
    only; None: at home) or home, parallel grippers open; collision shapes loaded but hidden."""
    import yourdfpy
    from viser.extras import ViserUrdf

    from robocfg.sim.loading import prepared_urdf

    path = prepared_urdf(robot)
    urdf = yourdfpy.URDF.load(path, build_scene_graph=True, load_meshes=True, build_collision_scene_graph=True,
                              load_collision_meshes=True,
                              filename_handler=partial(yourdfpy.filename_handler_magic, dir=path.parent))
    server.scene.add_frame(node, show_axes=False, position=tuple(mount[:3, 3]), wxyz=wxyz(mount[:3, :3]))
    shown = ViserUrdf(server, urdf, root_node_name=node, load_collision_meshes=True,
                      collision_mesh_color_override=(0.1, 0.7, 0.8, 0.5))
    shown.show_collision = False
    out = ShownRobot(robot, mount, node, urdf, shown)
    for k, arm in enumerate(robot.config.arms):
        q = q0 if (k == 0 and q0 is not None) else arm.home
        out.q.update(zip(robot.arm_joints(arm), (float(v) for v in q), strict=True))
        g = arm.gripper
        if isinstance(g, ParallelGripperConfig):  # one-jaw grippers included (a subclass)
            out.q.update(zip(robot.gripper_joints(arm), g.open, strict=True))
    return out


def draw_frames(scene: viser.SceneApi, f: ArmFrames, node: str) -> None:
    """Draw one arm's frames under ``node``: labelled triads, the ``ee_axis`` (magenta) and the
    finger pads' boxes (orange). Drawing again under the same node replaces the drawing."""
    for k, tri in enumerate(f.triads):
        name = f"{node}/triad{k}"
        scene.add_frame(name, axes_length=tri.length, axes_radius=tri.length * 0.05,
                        position=tuple(tri.pose[:3, 3]), wxyz=wxyz(tri.pose[:3, :3]))
        scene.add_label(f"{name}/label", tri.label, anchor=LABEL_ANCHORS[k])
    seg = np.array([[f.ee_axis.start, f.ee_axis.end]])
    scene.add_line_segments(f"{node}/ee_axis", seg, (200, 0, 200), thickness=4.0, thickness_units="screen")
    if f.pads:
        pads = np.array([[pad.corners[i], pad.corners[j]] for pad in f.pads for i, j in BOX_EDGES])
        scene.add_line_segments(f"{node}/pads", pads, (255, 140, 0), thickness=3.0, thickness_units="screen")
