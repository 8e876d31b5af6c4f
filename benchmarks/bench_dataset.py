"""Dataset recording cost: successful pick-place demos per core-minute without a dataset, with a
state-only dataset (joint actions; and with EE-delta actions too, ``--dataset-actions both``) and
with two 128x128 cameras (20 Hz; and with the wrist camera's depth); camera frames/s per renderer option;
size on disk and pyarrow load time of a larger state-only dataset.

    python benchmarks/bench_dataset.py --episodes 20 --camera-episodes 4 --size-episodes 1000 [--json out.json]

One process, one core: "per core-minute" = successes / (CPU minutes of the run, ``time.process_time``:
less sensitive to other jobs on a loaded machine than wall time, which is printed too). The
state-only ratio (dataset / none, CPU) is the cost of sampling, the command gate and writing
(goal ≤ 1.1×). Every row's imports are paid before the timings (a one-episode warm run, and the
writers' modules — pyarrow for LeRobot, h5py for HDF5 — imported first; their CPU ms are printed
as ``writer_first_import_ms``, a once-per-process cost no row pays). The rows run one after
another, so on a loaded machine they differ by ±15 % from noise alone;
``benchmarks/bench_control_cost.py --formats lerobot,hdf5`` alternates the formats episode by
episode and gives the per-episode cost. Camera frames/s: both task cameras rendered once per frame
while the arm moves (so the wrist camera's view changes every frame), per renderer (``--renderers``:
``robocfg.sim.camera_rig``: exact, tiny, egl).
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import json
import shutil
import tempfile
import time
from pathlib import Path

WRITER_MODULES = {"lerobot": ("pyarrow.parquet", "robocfg.datasets.lerobot"), "hdf5": ("robocfg.datasets.hdf5", "h5py")}


def _task(name: str, cameras: bool, size: int = 128, depth: bool = False):
    """The shipped task, its cameras at ``size`` (none without ``cameras``; ``depth``: the wrist
    camera records depth too)."""
    from robocfg.checks import load_task
    from robocfg.config import catalog

    t = load_task(catalog.find("tasks", name))
    cams = [c.model_copy(update={"width": size, "height": size, "depth": depth and c.name == "wrist"})
            for c in t.config.cameras] if cameras else []
    return dataclasses.replace(t, config=t.config.model_copy(update={"cameras": cams}))


def _run(task, episodes: int, seed: int, fmt: str | None, out: Path, actions: str = "joint") -> dict:
    from robocfg.datasets.language import pick_place_instruction
    from robocfg.datasets.sink import DatasetSink
    from robocfg.runners.pick_place import run_pick_place

    sink = None
    if fmt is not None:
        shutil.rmtree(out, ignore_errors=True)
        sink = DatasetSink(out, fmt, task, language=pick_place_instruction(task.config.pick_place),
                           extra_info={"task_path": str(task.path), "seed": seed, "arm": None, "robot_override": None},
                           actions=actions)  # type: ignore[arg-type]
    t0, c0 = time.perf_counter(), time.process_time()
    report, _ = run_pick_place(task, episodes, seed, sink=sink)
    if sink is not None:
        sink.close()
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    ok = report.summary.successes
    return {"episodes": episodes, "successes": ok, "wall_s": round(wall, 2), "cpu_s": round(cpu, 3),
            "demos_per_core_minute": round(ok / (cpu / 60.0), 1)}


def _render_rate(size: int, renderer: str, frames: int = 30) -> tuple[float, float]:
    """(frames per CPU second, frames per wall second) of rendering both task cameras once per
    frame (a frame = scene + wrist image), the arm moving a little between frames."""
    import numpy as np

    from robocfg.sim.camera_rig import CameraRig
    from robocfg.sim.world import World

    task = _task("pick_place", True, size)
    with World(task) as world:
        world.add_body(task.config.pick_place.object)
        arm = world.robot.arm()
        home = arm.joint_positions()
        rig = CameraRig(world, arm, task.config.cameras, renderer)  # type: ignore[arg-type]
        try:
            rig.render_all()
            t0, c0 = time.perf_counter(), time.process_time()
            for i in range(frames):
                world.robot.reset_joints(arm.joints, home + 0.1 * np.sin(0.3 * (i + 1)))
                rig.render_all()
            return frames / (time.process_time() - c0), frames / (time.perf_counter() - t0)
        finally:
            rig.close()


def _dir_size(root: Path) -> int:
    return sum(f.stat().st_size for f in root.rglob("*") if f.is_file())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=20, help="state-only rows")
    ap.add_argument("--camera-episodes", type=int, default=4, help="two-camera row")
    ap.add_argument("--size-episodes", type=int, default=1000, help="size-on-disk row (0: skip)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--renderers", default="exact,tiny,egl")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    from robocfg.sim.quiet import quiet_import

    quiet_import()
    res: dict = {"rows": {}, "writer_first_import_ms": {}}
    for fmt, modules in WRITER_MODULES.items():  # the writers' imports, once per process, out of the rows
        c0 = time.process_time()
        for m in modules:
            importlib.import_module(m)
        res["writer_first_import_ms"][fmt] = round((time.process_time() - c0) * 1e3, 1)
    import pyarrow.parquet as pq

    tmp = Path(tempfile.mkdtemp(prefix="bench_dataset_"))
    state, cams = _task("pick_place", False), _task("pick_place", True)
    _run(state, 1, args.seed, None, tmp / "warm")  # imports and caches out of the timings
    res["rows"]["no dataset"] = _run(state, args.episodes, args.seed, None, tmp / "none")
    res["rows"]["state-only lerobot"] = _run(state, args.episodes, args.seed, "lerobot", tmp / "state_lr")
    res["rows"]["state-only hdf5"] = _run(state, args.episodes, args.seed, "hdf5", tmp / "state_h5")
    res["rows"]["state-only lerobot, --dataset-actions both"] = _run(state, args.episodes, args.seed, "lerobot",
                                                                     tmp / "state_ee", actions="both")
    res["rows"]["2 cameras 128x128 lerobot"] = _run(cams, args.camera_episodes, args.seed, "lerobot", tmp / "cams")
    res["rows"]["2 cameras 128x128 + wrist depth lerobot"] = _run(_task("pick_place", True, depth=True),
                                                                  args.camera_episodes, args.seed, "lerobot",
                                                                  tmp / "cams_depth")
    base = res["rows"]["no dataset"]["cpu_s"] / args.episodes  # CPU seconds per episode
    for k in ("state-only lerobot", "state-only hdf5", "state-only lerobot, --dataset-actions both"):
        res["rows"][k]["cost_vs_none"] = round(res["rows"][k]["cpu_s"] / args.episodes / base, 3)
    for k in ("2 cameras 128x128 lerobot", "2 cameras 128x128 + wrist depth lerobot"):
        res["rows"][k]["cost_vs_none"] = round(res["rows"][k]["cpu_s"] / args.camera_episodes / base, 3)
    res["render_frames_per_s"] = {}
    for r in args.renderers.split(","):
        for size in (64, 128, 256):
            try:
                cpu_rate, wall_rate = _render_rate(size, r)
                res["render_frames_per_s"][f"{r} {size}x{size} x2 cameras"] = {"per_cpu_s": round(cpu_rate, 1),
                                                                               "per_wall_s": round(wall_rate, 1)}
            except Exception as exc:  # a renderer this machine lacks is reported, not fatal
                res["render_frames_per_s"][f"{r} {size}x{size} x2 cameras"] = f"unavailable: {exc}"
                break
    if args.size_episodes:
        root = tmp / "size"
        row = _run(state, args.size_episodes, args.seed, "lerobot", root)
        t0 = time.perf_counter()
        files = sorted(root.glob("data/chunk-*/file-*.parquet"))  # rolled over at 100 MB
        frames = sum(pq.read_table(p).num_rows for p in files)
        load = time.perf_counter() - t0
        row |= {"bytes_on_disk": _dir_size(root), "frames": frames, "data_files": len(files),
                "pyarrow_load_s": round(load, 4)}
        res["size"] = row
    shutil.rmtree(tmp, ignore_errors=True)
    print(json.dumps(res, indent=2))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2) + "\n")


if __name__ == "__main__":
    main()
