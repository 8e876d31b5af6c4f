"""A render-only copy of a world that TinyRenderer draws fast: low-poly meshes, static bodies baked.

TinyRenderer (CPU) spends its time on two things: the robot's visual meshes (a Panda has ≈ 100 000
triangles) and filling large triangles such as the ground. ``RenderMirror`` keeps its own
PyBullet clients that hold a proxy of every body of the source world, with each visual mesh
decimated to at most ``max_faces`` triangles (quadric decimation, cached on disk), and splits them
in two layers:

* static bodies (no joints, fixed base, not moved since the last bake: ground, table, pedestal,
  fixed obstacles) are rendered once per camera and size into a colour + depth background;
* everything else is rendered every frame, alone, and laid over the background by depth.

``mirror.render(camera, size)`` copies the source world's link poses to the proxies first, so it
shows the world's current state. A static body that moves later (a scripted obstacle) joins the
moving layer and the background is baked again. Frames: world, m; images (H, W, 3) uint8.
"""

from __future__ import annotations

import contextlib
import weakref
from dataclasses import dataclass, field

import numpy as np
import pybullet as p

from robocfg.sim.low_poly import MAX_FACES, Part, low_poly
from robocfg.sim.renderer import require_renderer

LINK_FRAME = 4  # getLinkState index of the URDF link frame's world position (then orientation)
GROW = 0.03  # m added around each moving link's collision box: visual meshes reach a little further
PAD = 3  # pixels around the moving bodies' window
POSE_TOL = 1e-6  # m / quaternion units: a baked body moved further than this is re-baked
BACKGROUNDS = 4  # baked backgrounds kept (one per fixed camera and size; a moving camera's changes every frame)
RENDERERS = ("auto", "tiny", "exact", "egl")  # see make_mirror; "exact": no mirror, the world's own meshes


@dataclass
class _Proxy:
    """Mirror bodies of one source body: (source link index, mirror body id) per link with visuals."""

    source: int
    layer: int  # the mirror client holding it
    links: list[tuple[int, int]] = field(default_factory=list)
    pose: tuple = ()  # base pose when baked (static layer only)


def crop_projection(proj, size: tuple[int, int], box: tuple[int, int, int, int]) -> list[float]:
    """The projection matrix (column-major 16-list) that draws only the pixels ``box`` = (x0, y0,
    x1, y1) (end exclusive) of an image of ``size`` = (W, H) drawn with ``proj``: an off-axis
    window, pixel for pixel the same as that part of the whole image, depth values unchanged."""
    w, h = size
    x0, y0, x1, y1 = box
    nx0, nx1 = 2 * x0 / w - 1, 2 * x1 / w - 1
    ny0, ny1 = 1 - 2 * y1 / h, 1 - 2 * y0 / h  # NDC y grows upwards, rows downwards
    sx, sy = 2 / (nx1 - nx0), 2 / (ny1 - ny0)
    window = np.array([[sx, 0, 0, -sx * (nx0 + nx1) / 2], [0, sy, 0, -sy * (ny0 + ny1) / 2],
                       [0, 0, 1, 0], [0, 0, 0, 1]])
    full = np.asarray(proj, float).reshape(4, 4).T
    return (window @ full).T.ravel().tolist()


def _cut_off(depth: np.ndarray, box: tuple[int, int, int, int], size: tuple[int, int]) -> bool:
    """Whether something drawn in the window touches one of its edges that is not an image edge."""
    x0, y0, x1, y1 = box
    w, h = size
    hit = depth < 1.0
    return bool((x0 > 0 and hit[:, 0].any()) or (x1 < w and hit[:, -1].any())
                or (y0 > 0 and hit[0].any()) or (y1 < h and hit[-1].any()))


def load_egl(client: int) -> None:
    """Load PyBullet's EGL renderer plugin into ``client`` (raises RobocfgError when it fails)."""
    import importlib.util

    from robocfg.errors import RobocfgError

    spec = importlib.util.find_spec("eglRenderer")
    if spec is None or spec.origin is None or p.loadPlugin(spec.origin, "_eglRendererPlugin",
                                                           physicsClientId=client) < 0:
        raise RobocfgError("PyBullet's EGL renderer plugin could not be loaded (no EGL driver?)")


def _disconnect(*clients: int) -> None:
    for c in clients:
        with contextlib.suppress(p.error):
            p.disconnect(physicsClientId=c)


class RenderMirror:
    """Render-only proxies of the bodies of PyBullet client ``source`` (see the module docstring).

    ``max_faces``: triangle budget per visual mesh (None: the original meshes). ``egl``: draw with
    PyBullet's EGL plugin (OpenGL: fast on a GPU; on a machine without one Mesa's llvmpipe runs it
    on the CPU, slower than TinyRenderer). Close it (or use it as a context manager) to free its two
    PyBullet clients.
    """

    def __init__(self, source: int, max_faces: int | None = MAX_FACES, egl: bool = False):
        require_renderer(source)  # its visual shapes are read from the source's renderer
        self.source = source
        self.max_faces = max_faces
        self.egl = egl
        self.moving = p.connect(p.DIRECT)
        self.renderer = p.ER_TINY_RENDERER
        if egl:  # one client (the plugin is one per process), loaded before any proxy: it only
            try:  # draws bodies made after it; a GPU needs no baked background
                load_egl(self.moving)
            except BaseException:
                _disconnect(self.moving)
                raise
            self.renderer = p.ER_BULLET_HARDWARE_OPENGL
        self.static = self.moving if egl else p.connect(p.DIRECT)
        self.proxies: dict[int, _Proxy] = {}
        self._background: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        self._finalizer = weakref.finalize(self, _disconnect, *{self.static, self.moving})

    def __enter__(self) -> RenderMirror:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        self._finalizer()
        self.static = self.moving = -1

    # ---- keeping the proxies in step with the source -------------------------------------
    def _is_static(self, body: int) -> bool:
        s = self.source
        return (p.getNumJoints(body, physicsClientId=s) == 0
                and p.getDynamicsInfo(body, -1, physicsClientId=s)[0] == 0.0)

    def _base_pose(self, body: int) -> tuple:
        pos, quat = p.getBasePositionAndOrientation(body, physicsClientId=self.source)
        return (*pos, *quat)

    def _build(self, body: int, layer: int) -> _Proxy:
        """Mirror bodies for the visual shapes of ``body`` (a link may have several: multi-material
        meshes split into parts, URDF links with several ``<visual>`` elements)."""
        proxy = _Proxy(body, layer)
        for vs in p.getVisualShapeData(body, physicsClientId=self.source):
            for vis in self._visuals(vs, layer):
                proxy.links.append((vs[1], p.createMultiBody(baseMass=0.0, baseVisualShapeIndex=vis,
                                                             physicsClientId=layer)))
        return proxy

    def _visuals(self, vs, layer: int) -> list[int]:
        """Mirror visual shapes for one ``getVisualShapeData`` entry, in its local frame."""
        kind, dims, fname, pos, orn, rgba = vs[2], vs[3], vs[4], vs[5], vs[6], vs[7]
        frame = dict(visualFramePosition=list(pos), visualFrameOrientation=list(orn), physicsClientId=layer)
        if kind == p.GEOM_MESH:
            name = fname.decode() if isinstance(fname, bytes) else str(fname)
            parts = low_poly(name, rgba, self.max_faces) if self.max_faces is not None else [Part(name, rgba)]
            return [p.createVisualShape(p.GEOM_MESH, fileName=part.path, meshScale=list(dims),
                                        rgbaColor=list(part.rgba), **frame) for part in parts]
        kw = dict(rgbaColor=list(rgba), **frame)
        if kind == p.GEOM_BOX:
            return [p.createVisualShape(p.GEOM_BOX, halfExtents=[d / 2 for d in dims], **kw)]
        if kind == p.GEOM_SPHERE:
            return [p.createVisualShape(p.GEOM_SPHERE, radius=dims[0], **kw)]
        if kind in (p.GEOM_CYLINDER, p.GEOM_CAPSULE):
            return [p.createVisualShape(kind, length=dims[0], radius=dims[1], **kw)]
        if kind == p.GEOM_PLANE:
            return [p.createVisualShape(p.GEOM_PLANE, planeNormal=[0, 0, 1], **kw)]
        return []

    def _link_poses(self, proxy: _Proxy) -> dict[int, tuple]:
        """World pose (position, quaternion xyzw) of every source link the proxy draws."""
        s, b = self.source, proxy.source
        links = sorted({k for k, _ in proxy.links if k >= 0})
        out = {-1: p.getBasePositionAndOrientation(b, physicsClientId=s)}
        if links:
            for k, st in zip(links, p.getLinkStates(b, links, physicsClientId=s), strict=True):
                out[k] = (st[LINK_FRAME], st[LINK_FRAME + 1])
        return out

    def _place(self, proxy: _Proxy) -> None:
        poses = self._link_poses(proxy)
        for link, mb in proxy.links:
            pos, quat = poses[link]
            p.resetBasePositionAndOrientation(mb, pos, quat, physicsClientId=proxy.layer)

    def sync(self) -> None:
        """Proxies for bodies new in the source; a baked body that moved joins the moving layer."""
        s = self.source
        for i in range(p.getNumBodies(physicsClientId=s)):
            b = p.getBodyUniqueId(i, physicsClientId=s)
            if b not in self.proxies:
                static = self._is_static(b) and not self.egl
                proxy = self.proxies[b] = self._build(b, self.static if static else self.moving)
                if static:
                    self._place(proxy)
                    proxy.pose = self._base_pose(b)
                    self._background.clear()
        for proxy in self.proxies.values():
            if proxy.pose and max(abs(a - b) for a, b in zip(self._base_pose(proxy.source), proxy.pose,
                                                             strict=True)) > POSE_TOL:
                for _, mb in proxy.links:
                    p.removeBody(mb, physicsClientId=self.static)
                moved = self._build(proxy.source, self.moving)
                proxy.layer, proxy.links, proxy.pose = moved.layer, moved.links, ()
                self._background.clear()

    # ---- rendering -------------------------------------------------------------------------
    def render(self, view: list[float], proj: list[float], size: tuple[int, int],
               light_direction=(1.0, 1.0, 2.0), shadow: bool = False) -> np.ndarray:
        """RGB (H, W, 3) uint8 of the source world now, seen through PyBullet ``view``/``proj``
        matrices (column-major 16-lists) at ``size`` = (W, H) pixels."""
        return self.render_rgbd(view, proj, size, light_direction, shadow)[0]

    def render_rgbd(self, view: list[float], proj: list[float], size: tuple[int, int],
                    light_direction=(1.0, 1.0, 2.0), shadow: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """(RGB (H, W, 3) uint8, depth buffer (H, W) float32 in PyBullet's [0, 1] form) of the
        source world now; see :meth:`render`."""
        self.sync()
        if self.egl:
            for proxy in self.proxies.values():
                self._place(proxy)
            rgb, depth = self._draw(self.moving, view, proj, size, light_direction, shadow)
            return rgb.copy(), depth.copy()
        key = (tuple(view), tuple(proj), tuple(size), tuple(light_direction), shadow)
        if key not in self._background:
            while len(self._background) >= BACKGROUNDS:  # the oldest goes (a moving camera's, often)
                self._background.pop(next(iter(self._background)))
            self._background[key] = self._draw(self.static, view, proj, size, light_direction, shadow)
        bg_rgb, bg_depth = self._background[key]
        moving = [pr for pr in self.proxies.values() if pr.layer == self.moving]
        for proxy in moving:
            self._place(proxy)
        out, out_depth = bg_rgb.copy(), bg_depth.copy()
        box = self._window(moving, view, proj, size)
        if box is None:
            return out, out_depth
        x0, y0, x1, y1 = box
        rgb, depth = self._draw(self.moving, view, crop_projection(proj, size, box), (x1 - x0, y1 - y0),
                                light_direction, shadow)
        if _cut_off(depth, box, size):  # a visual reaches past its link's collision box: draw it all
            x0, y0, x1, y1 = 0, 0, size[0], size[1]
            rgb, depth = self._draw(self.moving, view, proj, size, light_direction, shadow)
        near = depth < bg_depth[y0:y1, x0:x1]
        out[y0:y1, x0:x1][near] = rgb[near]
        out_depth[y0:y1, x0:x1][near] = depth[near]
        return out, out_depth

    def _window(self, moving: list[_Proxy], view, proj, size) -> tuple[int, int, int, int] | None:
        """Pixel box (x0, y0, x1, y1), end exclusive, around the moving bodies: their links' boxes in
        the source world grown by :data:`GROW` m and :data:`PAD` pixels. The whole image when a
        corner is behind the camera; None when nothing moving is in view."""
        s = self.source
        lows, highs = [], []
        for proxy in moving:
            for link in {k for k, _ in proxy.links}:
                lo, hi = p.getAABB(proxy.source, link, physicsClientId=s)
                lows.append(lo)
                highs.append(hi)
        if not lows:
            return None
        lo, hi = np.min(lows, axis=0) - GROW, np.max(highs, axis=0) + GROW
        corners = np.array([[(hi if k >> a & 1 else lo)[a] for a in range(3)] + [1.0] for k in range(8)])
        clip = corners @ (np.asarray(proj, float).reshape(4, 4).T @ np.asarray(view, float).reshape(4, 4).T).T
        w, h = size
        if (clip[:, 3] <= 1e-6).any():
            return 0, 0, w, h
        ndc = clip[:, :2] / clip[:, 3:4]
        x = (ndc[:, 0] + 1) / 2 * w
        y = (1 - ndc[:, 1]) / 2 * h
        x0, x1 = max(0, int(x.min()) - PAD), min(w, int(np.ceil(x.max())) + PAD)
        y0, y1 = max(0, int(y.min()) - PAD), min(h, int(np.ceil(y.max())) + PAD)
        return (x0, y0, x1, y1) if x1 > x0 and y1 > y0 else None

    def _draw(self, client: int, view, proj, size, light_direction, shadow) -> tuple[np.ndarray, np.ndarray]:
        w, h = size
        img = p.getCameraImage(w, h, view, proj, renderer=self.renderer, shadow=int(shadow),
                               lightDirection=list(light_direction), flags=p.ER_NO_SEGMENTATION_MASK,
                               physicsClientId=client)
        rgb = np.reshape(np.asarray(img[2], dtype=np.uint8), (h, w, 4))[:, :, :3]
        return rgb, np.reshape(np.asarray(img[3], dtype=np.float32), (h, w))


def make_mirror(client: int, renderer: str, max_faces: int | None) -> RenderMirror:
    """The render mirror for ``renderer`` (``"auto"``: EGL where an NVIDIA GPU is present and the
    plugin loads, else TinyRenderer)."""
    from pathlib import Path

    from robocfg.errors import RobocfgError

    if renderer == "egl" or (renderer == "auto" and Path("/dev/nvidiactl").exists()):
        try:
            return RenderMirror(client, max_faces, egl=True)
        except RobocfgError:
            if renderer == "egl":
                raise
    return RenderMirror(client, max_faces)
