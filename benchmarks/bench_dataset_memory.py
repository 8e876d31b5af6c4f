"""Peak memory of a recording run with a depth camera: the LeRobot writer's depth frames in memory.

    python benchmarks/bench_dataset_memory.py [--episodes 50] [--size 128] [--code PATH] [--json out.json]

Runs ``python -m robocfg run pick-place TASK -n EPISODES --workers 1 --keep all --dataset DIR
--dataset-format lerobot`` in a fresh process, where TASK is the shipped pick-place task with its
wrist camera only, ``size``×``size`` pixels, with depth (64 KiB a frame at 128×128, 20 Hz). Prints
the child's peak resident memory (``ru_maxrss``), the dataset's size and its data parquet's row
groups. ``--code PATH`` runs the robocfg found at PATH (another checkout) instead of this one, for
a before/after figure of the same command.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def depth_task(tmp: Path, size: int) -> Path:
    import yaml

    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    cams = [c for c in doc["cameras"] if c["name"] == "wrist"]
    for c in cams:
        c["width"] = c["height"] = size
        c["depth"] = True
    doc["cameras"] = cams
    path = tmp / "pick_place_wrist_depth.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=50)
    ap.add_argument("--size", type=int, default=128, help="camera width and height (pixels)")
    ap.add_argument("--code", default=str(ROOT), help="the robocfg checkout to run (default: this one)")
    ap.add_argument("--json", default=None)
    args = ap.parse_args()

    import pyarrow.parquet as pq

    tmp = Path(tempfile.mkdtemp(prefix="bench_dataset_memory_"))
    task, out = depth_task(tmp, args.size), tmp / "ds"
    env = {**os.environ, "PYTHONPATH": str(Path(args.code).resolve())}
    cmd = [sys.executable, "-m", "robocfg", "run", "pick-place", str(task), "-n", str(args.episodes), "--seed", "0",
           "--workers", "1", "--keep", "all", "--dataset", str(out), "--dataset-format", "lerobot", "-q"]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, cwd=args.code, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode not in (0, 1):
        sys.exit(f"run failed ({p.returncode}):\n{p.stderr[-3000:]}")
    peak_mib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024  # Linux: KiB
    data_files = sorted(out.glob("data/chunk-*/file-*.parquet"))  # rolled over at 100 MB
    row_groups = sum(pq.ParquetFile(p).num_row_groups for p in data_files)
    size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
    info = json.loads((out / "meta/info.json").read_text())
    row = {"code": args.code, "episodes": args.episodes, "size": args.size, "frames": info["total_frames"],
           "peak_rss_mib": peak_mib, "dataset_mib": size / 2**20, "row_groups": row_groups,
           "data_files": len(data_files), "wall_s": wall}
    print(f"code {args.code}: {args.episodes} episodes, {info['total_frames']} frames of {args.size}x{args.size} "
          f"depth: peak RSS {peak_mib:.0f} MiB, dataset {size / 2**20:.0f} MiB, data row groups {row_groups} in {len(data_files)} file(s), "
          f"wall {wall:.0f} s (load average {os.getloadavg()[0]:.2f})")
    if args.json:
        Path(args.json).write_text(json.dumps(row, indent=2) + "\n")


if __name__ == "__main__":
    main()
