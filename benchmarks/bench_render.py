"""What a recording costs: frames/s per renderer and image size, and recorded/unrecorded run time.

    python benchmarks/bench_render.py [--frames 20] [--repeats 3] [--kinds pick-place,gripper,follow-target]
                                      [--renderers exact,full,tiny,tiny500[,egl]] [--json out.json]

Part 1 renders the default pick-place scene (Panda at home, the cube) ``--frames`` times per
renderer and image size, in one process: ``exact`` = the world's own meshes through
``getCameraImage`` (what recordings did before); ``full`` = the render mirror with the original
meshes (static bodies baked once, the rest drawn alone and merged by depth); ``tiny`` = the mirror
with meshes cut to ``MAX_FACES`` (1000) triangles (the default); ``tiny500`` = 500 triangles; ``egl`` = the mirror
through PyBullet's EGL plugin (OpenGL; on a machine without a GPU Mesa's llvmpipe runs it on the
CPU). ms/frame is CPU time of this process (less sensitive to other jobs than wall time; llvmpipe's
worker threads count too); frames/s is wall-clock.

Part 2 runs ``robocfg run KIND -q`` with and without ``--record out.gif`` (default settings),
interleaved, ``--repeats`` times each, as separate processes (what a user waits for: imports,
world build, the run, encoding). The ratio is recorded/unrecorded of the median CPU time of the
child (user + system), and of the median wall time. ``ROBOCFG_RENDERER`` is set per row.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from robocfg.sim.low_poly import MAX_FACES

SIZES = ((160, 120), (240, 180), (320, 240), (480, 360), (640, 480))
FACES = {"full": None, "tiny": MAX_FACES, "tiny500": 500, "egl": MAX_FACES}


def renderer_rates(renderers: list[str], frames: int) -> list[dict]:
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.checks import load_task
    from robocfg.config import catalog
    from robocfg.sim.record_camera import render, scene_camera, view_projection
    from robocfg.sim.render_mirror import RenderMirror
    from robocfg.sim.world import World

    task = load_task(catalog.find("tasks", "pick_place"))
    rows = []
    with World(task) as world:
        world.add_body(task.config.pick_place.object)
        for name in renderers:
            mirror = None if name == "exact" else RenderMirror(world.client, FACES[name], egl=name == "egl")
            try:
                for size in SIZES:
                    cam = scene_camera(world, size)
                    view, proj = view_projection(world.client, cam, size)

                    def draw(cam=cam, view=view, proj=proj, size=size, mirror=mirror):
                        if mirror is None:
                            return render(world.client, cam, size)
                        return mirror.render(view, proj, size)

                    draw()  # the mirror bakes its background (and builds its proxies) on the first frame
                    c0, w0 = time.process_time(), time.perf_counter()
                    for _ in range(frames):
                        draw()
                    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
                    rows.append({"renderer": name, "size": f"{size[0]}x{size[1]}",
                                 "cpu_ms_per_frame": 1000 * cpu / frames, "frames_per_s": frames / wall})
                    print(f"{name:8s} {size[0]:4d}x{size[1]:<4d} {1000 * cpu / frames:7.1f} ms CPU/frame "
                          f"{frames / wall:7.1f} frames/s", flush=True)
            finally:
                if mirror is not None:
                    mirror.close()
    return rows


def _child(cmd: list[str], env: dict) -> tuple[float, float]:
    """(CPU s of the child, wall s)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), wall


def record_ratios(kinds: list[str], repeats: int, renderers: list[str]) -> list[dict]:
    rows = []
    exe = [sys.executable, "-m", "robocfg", "run"]
    with tempfile.TemporaryDirectory() as tmp:
        for kind in kinds:
            for renderer in renderers:
                env = dict(os.environ, ROBOCFG_RENDERER=renderer)
                plain, recorded = [], []
                for k in range(repeats):
                    plain.append(_child([*exe, kind, "-q"], env))
                    recorded.append(_child([*exe, kind, "-q", "--record", f"{tmp}/{kind}{k}.gif"], env))
                cpu0, cpu1 = (statistics.median(c for c, _ in xs) for xs in (plain, recorded))
                wall0, wall1 = (statistics.median(w for _, w in xs) for xs in (plain, recorded))
                row = {"kind": kind, "renderer": renderer, "cpu_s": cpu0, "cpu_s_recorded": cpu1,
                       "cpu_ratio": cpu1 / cpu0, "wall_s": wall0, "wall_s_recorded": wall1, "wall_ratio": wall1 / wall0}
                rows.append(row)
                print(f"{kind:14s} {renderer:6s} CPU {cpu0:5.2f} s → {cpu1:5.2f} s ({cpu1 / cpu0:4.2f}×)   "
                      f"wall {wall0:5.2f} s → {wall1:5.2f} s ({wall1 / wall0:4.2f}×)", flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--kinds", default="pick-place,gripper,follow-target")
    ap.add_argument("--renderers", default="exact,full,tiny,tiny500",
                    help="part 1 (add egl to try PyBullet's EGL plugin)")
    ap.add_argument("--record-renderers", default="exact,tiny",
                    help="ROBOCFG_RENDERER values for part 2 (auto, tiny, exact, egl)")
    ap.add_argument("--skip-frames", action="store_true", help="part 2 only")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    out: dict = {"load_average": os.getloadavg()}
    if not args.skip_frames:
        out["frames"] = renderer_rates(args.renderers.split(","), args.frames)
    kinds = [k for k in args.kinds.split(",") if k]
    if kinds:
        out["recording"] = record_ratios(kinds, args.repeats, args.record_renderers.split(","))
    out["load_average_end"] = os.getloadavg()
    print(f"load average {out['load_average'][0]:.1f} → {out['load_average_end'][0]:.1f}")
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
