"""The browser viewer of ``robocfg view``: a viser page showing the robot(s) with their real
meshes, the frames of :mod:`robocfg.viewer.frames`, joint sliders, a collision-shape toggle, and
a target gizmo the first arm follows by our own IK (``KinematicModel.ik``).

viser (not meshcat) because it serves its client from the wheel (no download, works on a headless
machine through an SSH tunnel), has GUI widgets (sliders, checkboxes, markdown) and a transform
gizmo, and draws URDFs from yourdfpy, which robocfg already uses. Meshes come from the same URDF
PyBullet loads (``package://`` resolved, attachments composed). Poses: world frame, metres; a task
YAML's robots stand at their mounts, with its table, pedestal, objects, obstacles, place target and
the frusta of its dataset cameras (a wrist camera moves with the arm).

``reload()`` rebuilds the page from the YAML; when the YAML is invalid the page shows its
``FILE:LINE:COL: field: message`` lines instead (``errors`` holds them).
"""

from __future__ import annotations

import contextlib
import io
import threading
import time
from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robocfg.checks import CheckedTask
from robocfg.errors import ConfigError
from robocfg.geometry.pose import pose_matrix, pose_to_matrix
from robocfg.viewer.frames import ArmFrames, arm_frames, pad_boxes_ee
from robocfg.viewer.frusta import ShownCamera, add_frusta
from robocfg.viewer.playback import Playback
from robocfg.viewer.scenery import add_scenery
from robocfg.viewer.shown import ShownRobot, add_robot, draw_frames, set_value, wxyz
from robocfg.viewer.source import ViewSource

if TYPE_CHECKING:
    import viser

    from robocfg.kinematics.model import KinematicModel


class BrowserViewer:
    """A viser server showing ``source``; see the module docstring."""

    def __init__(self, source: ViewSource, host: str = "127.0.0.1", port: int = 8080,
                 q: Sequence[float] | None = None, playback: Playback | None = None):
        import viser

        self.source, self.q0 = source, None if q is None else list(q)
        self.playback = playback
        self.scenery: dict[str, viser.GlbHandle] = {}
        self._playing = threading.Event()
        self._player: threading.Thread | None = None
        with contextlib.redirect_stdout(io.StringIO()):  # viser prints a banner whatever ``verbose`` says
            self.server = viser.ViserServer(host=host, port=port, verbose=False)
        self.lock = threading.RLock()
        self.robots: list[ShownRobot] = []
        self.frames: list[ArmFrames] = []
        self.sliders: dict[str, viser.GuiSliderHandle[float]] = {}
        self.cameras: list[ShownCamera] = []
        self.errors: list[str] = []
        self.watched: list[Path] = [source.path]
        self.ik_status = ""
        self._model: KinematicModel | None = None
        self._syncing = False
        try:
            self.reload()
        except BaseException:  # Ctrl-C while loading: stop the server quietly
            self.stop()
            raise

    @property
    def url(self) -> str:
        return f"http://{self.server.get_host()}:{self.server.get_port()}"

    # ---- building -----------------------------------------------------------------------
    def reload(self) -> None:
        """Rebuild the page from the YAML (or show its errors)."""
        with self.lock:
            self.server.scene.reset()
            self.server.gui.reset()
            self.robots, self.frames, self.sliders, self._model = [], [], {}, None
            self.cameras = []
            try:
                checked = self.source.load()
            except ConfigError as exc:
                self.errors = [p.format() for p in exc.problems]
                text = "\n".join(self.errors)
                self.server.gui.add_markdown(f"**{self.source.path.name} is invalid** (fix it and save):\n\n```\n{text}\n```")
                return
            self.errors = []
            robots = self.source.robots(checked)
            self.watched = [self.source.path, *(r.path for r in robots)]
            task = checked if isinstance(checked, CheckedTask) else None
            mounts = [np.eye(4)] if task is None else [pose_matrix(m) for m in task.config.robots]
            if task is not None:
                self.scenery = add_scenery(self.server, task)
            for k, (robot, mount) in enumerate(zip(robots, mounts, strict=True)):
                q0 = self.q0 if not self.robots else None
                self.robots.append(add_robot(self.server, robot, mount, f"/robot{k}", q0))
            if task is not None:
                self.cameras = add_frusta(self.server, list(task.config.cameras), self._ee_pose(), wxyz)
            self._add_gui()
            if self.playback is not None:
                self._add_playback_gui(self.playback)
            self.refresh()
            self._fit_camera()

    def _fit_camera(self) -> None:
        """Ground grid and initial camera sized to the robots (a 3 m KR210 as well as a Panda)."""
        pts = np.array([r.link_pose(link)[:3, 3] for r in self.robots for link in r.urdf.link_map])
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        size = float(max(np.max(hi - lo), 0.3))
        centre = (lo + hi) / 2
        cell = 0.1 if size < 2 else 0.25
        self.server.scene.add_grid("/ground", width=3 * size, height=3 * size, cell_size=cell, section_size=5 * cell,
                                   position=(float(centre[0]), float(centre[1]), 0.0))
        self.server.initial_camera.look_at = tuple(centre)
        self.server.initial_camera.position = tuple(centre + size * np.array([1.0, -0.85, 0.55]))

    def _add_gui(self) -> None:
        gui, first = self.server.gui, self.robots[0]
        gui.add_markdown(f"**{self.source.path.name}** ({self.source.kind}) — frames: base, ee_link, TCP, "
                         "grasp (x approach, y closing); magenta: ee_axis; orange: finger pads")
        coll = gui.add_checkbox("collision shapes", False)

        @coll.on_update
        def _(_event) -> None:
            for r in self.robots:
                r.shown.show_collision = coll.value

        self.collision_checkbox = coll
        limits = first.shown.get_actuated_joint_limits()
        with gui.add_folder("joints"):
            for name in first.urdf.actuated_joint_names:
                lo, hi = limits[name]
                lo, hi = (-np.pi, np.pi) if lo is None or hi is None else (lo, hi)
                s = gui.add_slider(name, min=float(lo), max=float(hi), step=float(hi - lo) / 200,
                                   initial_value=float(np.clip(first.q.get(name, 0.0), lo, hi)))
                s.on_update(partial(self._on_slider, name))
                self.sliders[name] = s
        self._ik_text = gui.add_markdown("drag the gizmo at the TCP: the first arm follows by IK")
        T = first.link_pose(first.checked.config.arms[0].ee_link)
        from robocfg.kinematics.frames import tcp_from_ee

        T_tcp = tcp_from_ee(T, first.checked.config.arms[0])
        size = float(np.clip(1.5 * first.checked.config.arms[0].tcp_offset, 0.08, 0.5))
        self.target = self.server.scene.add_transform_controls("/target", scale=size, position=tuple(T_tcp[:3, 3]),
                                                               wxyz=wxyz(T_tcp[:3, :3]))
        self.target.on_update(lambda _event: self.follow_target())

    def _add_playback_gui(self, pb: Playback) -> None:
        gui = self.server.gui
        outcome = "" if pb.success is None else ("succeeded" if pb.success else f"failed ({pb.reason})")
        phases = ", ".join(f"{name or 'start'} {t:.2f} s" for name, t in pb.phases())
        with gui.add_folder("playback"):
            gui.add_markdown(f"recorded run, {pb.duration:.2f} s simulated, {outcome}  \nphases: {phases}")
            self.time_slider = gui.add_slider("t (s)", min=0.0, max=max(pb.duration, 1e-3),
                                              step=max(pb.duration, 1e-3) / 500, initial_value=0.0)
            self.time_slider.on_update(lambda _event: self.show_time(float(self.time_slider.value)))
            self._phase_text = gui.add_markdown("")
            play = gui.add_button("play / pause")
            play.on_click(lambda _event: self.toggle_play())
        self.show_time(0.0)

    def show_time(self, t: float) -> None:
        """Pose the robots and the free bodies as the playback has them at time ``t`` (s)."""
        if self.playback is None:
            return
        with self.lock:
            frame = self.playback.at(t)
            for robot, q in zip(self.robots, frame.joints, strict=False):
                robot.q.update(q)
            for name, (pos, quat) in frame.bodies.items():
                handle = self.scenery.get(name)
                if handle is not None:
                    x, y, z, w = quat
                    handle.position, handle.wxyz = pos, (w, x, y, z)
            self._phase_text.content = f"t = {frame.t:.2f} s, phase: {frame.phase or 'start'}"
            self.refresh()

    def toggle_play(self) -> None:
        """Start playing from the slider's time in real time (from the start once at the end), or pause."""
        if self._playing.is_set():
            self._playing.clear()
            return
        self._playing.set()
        self._player = threading.Thread(target=self._play, daemon=True)
        self._player.start()

    def _play(self, step: float = 1 / 30) -> None:
        assert self.playback is not None
        t = float(self.time_slider.value)
        if t >= self.playback.duration - 1e-6:
            t = 0.0
        start = time.monotonic() - t
        while self._playing.is_set() and t < self.playback.duration:
            t = min(time.monotonic() - start, self.playback.duration)
            set_value(self.time_slider, t)  # its update handler poses the scene
            time.sleep(step)
        self._playing.clear()

    # ---- updates ------------------------------------------------------------------------
    def _on_slider(self, name: str, _event) -> None:
        if not self._syncing:
            self.set_joint(name, float(self.sliders[name].value))

    def set_joint(self, name: str, value: float) -> None:
        """Move one joint of the first robot (as its slider does); the gizmo goes to the new TCP."""
        with self.lock:
            self.robots[0].q[name] = float(value)
            self.refresh()
            T = self.frames[0].triads[2].pose
            self.target.position, self.target.wxyz = tuple(T[:3, 3]), wxyz(T[:3, :3])

    def follow_target(self) -> None:
        """IK of the first arm to the gizmo's pose (TCP), seeded at the current joints."""
        from robocfg.kinematics.model import KinematicModel

        with self.lock:
            first = self.robots[0]
            arm = first.checked.config.arms[0]
            if self._model is None:
                self._model = KinematicModel.from_robot(first.checked, base_pose=first.mount)
            w, x, y, z = self.target.wxyz
            T = pose_to_matrix(self.target.position, (x, y, z, w))
            joints = first.checked.arm_joints(arm)
            seed = np.array([first.q[j] for j in joints])
            res = self._model.ik(T, seed_q=seed, time_budget=0.05)
            first.q.update(zip(joints, res.q.tolist(), strict=True))
            self.refresh()
            self.ik_status = ("converged" if res.converged else "not reachable, closest shown") + \
                f" (residual {res.pos_err * 1000:.1f} mm, {np.degrees(res.rot_err):.1f}°)"
            self._ik_text.content = f"IK: {self.ik_status}"

    def refresh(self) -> None:
        """Send joint values, redraw the frames, move the sliders to the joint values."""
        with self.lock:
            self.frames = []
            for r in self.robots:
                r.apply()
                length = 0.08 if r.checked.config.arms[0].tcp_offset < 0.15 else 0.2
                for arm in r.checked.config.arms:
                    f = arm_frames(arm, r.link_pose, pad_boxes_ee(r.checked, arm), length)
                    self.frames.append(f)
                    draw_frames(self.server.scene, f, f"{r.node}_frames/{arm.name}")
            T_ee = self._ee_pose()
            for cam in self.cameras:
                if cam.camera.mount == "ee":
                    cam.place(T_ee, wxyz)
            self._syncing = True
            try:
                for name, s in self.sliders.items():
                    v = self.robots[0].q.get(name, 0.0)
                    if abs(s.value - v) > 1e-9:
                        set_value(s, v)
            finally:
                self._syncing = False

    def _ee_pose(self) -> np.ndarray | None:
        """World pose of the first arm's ``ee_link`` (where ``mount: ee`` cameras sit)."""
        if not self.robots:
            return None
        first = self.robots[0]
        return first.link_pose(first.checked.config.arms[0].ee_link)

    def scene_names(self) -> list[str]:
        """Names of the scene nodes the server holds (robot links, frames, scenery)."""
        return sorted(self.server.scene._handle_from_node_name)  # viser keeps no public listing

    def stop(self) -> None:
        self._playing.clear()
        with contextlib.redirect_stdout(io.StringIO()):  # and "(viser) Server stopped"
            self.server.stop()
