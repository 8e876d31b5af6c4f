"""How far a LeRobot recording gets before its files roll over at lerobot's default limits (data
files 100 MB, video files 200 MB; 1 MB = 2**20 bytes), for the default pick-place task recorded
state only, with its two cameras, and with the wrist camera's depth too.

Records a few episodes of each (one process, 20 Hz by default) and reports per frame: the Arrow
size of the data rows (what the writer counts towards ``data_files_size_in_mb``), the data
parquet's size on disk, each camera's MP4 bytes (what counts towards ``video_files_size_in_mb``);
then how many frames and episodes fit in one data file and one video file. A run with more
episodes than that writes a second file.

    python benchmarks/bench_dataset_files.py --episodes 3
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def _task(tmp: Path, cameras: str, size: int) -> Path:
    import yaml

    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    if cameras == "none":
        doc.pop("cameras")
    else:
        for cam in doc["cameras"]:
            cam["width"] = cam["height"] = size
        doc["cameras"][1]["depth"] = cameras == "rgb+depth"
    path = tmp / f"pick_place_{cameras}.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def measure(tmp: Path, cameras: str, episodes: int, size: int, fps: int) -> dict:
    import pyarrow.parquet as pq

    from robocfg.checks import load_task
    from robocfg.datasets.files import MB, FileLimits
    from robocfg.datasets.language import pick_place_instruction
    from robocfg.datasets.lerobot_meta import data_files
    from robocfg.datasets.sink import DatasetSink
    from robocfg.runners.pick_place import run_pick_place

    task = load_task(_task(tmp, cameras, size))
    out = tmp / f"ds_{cameras}"
    sink = DatasetSink(out, "lerobot", task, fps=fps, keep="all", language=pick_place_instruction(task.config.pick_place))
    run_pick_place(task, episodes, seed=0, sink=sink)
    sink.close()
    files = data_files(out)
    frames = sum(pq.ParquetFile(p).metadata.num_rows for p in files)
    feats = json.loads((out / "meta/info.json").read_text())["features"]
    # the Arrow size the writer counts: 4 bytes a float32 value, 8 an int64, no validity bitmaps
    arrow = sum(8 if f["dtype"] == "int64" else 4 * math.prod(f["shape"]) for f in feats.values() if f["dtype"] != "video")
    disk = sum(p.stat().st_size for p in files) / frames
    limits = FileLimits()
    per_episode = frames / episodes
    row = {"cameras": cameras, "size": size, "episodes": episodes, "frames": frames, "data_files": len(files),
           "data_arrow_bytes_per_frame": round(arrow, 1), "data_disk_bytes_per_frame": round(disk, 1),
           "frames_per_data_file": int(limits.data_files_size_in_mb * MB // arrow),
           "episodes_per_data_file": int(limits.data_files_size_in_mb * MB / arrow / per_episode)}
    for video in sorted((out / "videos").glob("*")) if (out / "videos").is_dir() else []:
        per_frame = sum(p.stat().st_size for p in video.rglob("*.mp4")) / frames
        row[video.name] = {"mp4_bytes_per_frame": round(per_frame, 1),
                           "episodes_per_video_file": int(limits.video_files_size_in_mb * MB / per_frame / per_episode)}
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--episodes", type=int, default=3)
    ap.add_argument("--size", type=int, default=128, help="camera width and height (pixels)")
    ap.add_argument("--fps", type=int, default=20)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_dataset_files_"))
    try:
        rows = [measure(tmp, cams, args.episodes, args.size, args.fps) for cams in ("none", "rgb", "rgb+depth")]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    for r in rows:
        videos = "; ".join(f"{k}: {v['mp4_bytes_per_frame']} B/frame, {v['episodes_per_video_file']} episodes/200 MB"
                           for k, v in r.items() if isinstance(v, dict))
        print(f"{r['cameras']:>9}: {r['frames']} frames / {r['episodes']} episodes; data {r['data_arrow_bytes_per_frame']} "
              f"B/frame Arrow ({r['data_disk_bytes_per_frame']} on disk) -> {r['frames_per_data_file']} frames, "
              f"{r['episodes_per_data_file']} episodes per 100 MB file" + (f"; {videos}" if videos else ""))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
