"""By hand, not CI: a multi-file LeRobot dataset (rolled over at small limits) read by the real
lerobot returns, in its second and last data and video files (a later chunk), the values robocfg wrote.

Two steps, two interpreters:

1. ``record`` (the project's venv): records a pick-place run with a scene camera and a wrist
   camera with depth, ``--dataset-data-mb`` / ``--dataset-video-mb`` small enough for several
   files, and saves what the writer was handed (every episode's state, actions, depth and RGB
   frames) to ``OUT.expected.npz`` beside the dataset.
2. ``check`` (a scratch venv with lerobot 0.4.x + torch, never the project's):
   ``LeRobotDataset("local/check", root=OUT, video_backend="pyav")``; for frames of episodes in
   the second and the last data file and video file of each camera it compares what lerobot
   returns with what was written: state, actions and depth exactly, RGB frames decoded from the
   MP4 (lossy H.264) to the written frame, and to the frames beside it (the right frame is the
   nearest one).

    python benchmarks/check_lerobot_multifile.py record /tmp/lr_multi --episodes 8
    /tmp/datafeat_lerobot/bin/python benchmarks/check_lerobot_multifile.py check /tmp/lr_multi
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def record(out: Path, episodes: int, size: int, data_mb: float, video_mb: float, chunk_files: int) -> None:
    sys.path.insert(0, str(ROOT))
    import yaml

    from robocfg.checks import load_task
    from robocfg.datasets.files import FileLimits
    from robocfg.datasets.language import pick_place_instruction
    from robocfg.datasets.lerobot import LeRobotWriter
    from robocfg.datasets.sink import DatasetSink
    from robocfg.runners.pick_place import run_pick_place

    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    for cam in doc["cameras"]:
        cam["width"] = cam["height"] = size
    doc["cameras"][1]["depth"] = True  # the wrist camera
    task_file = out.parent / f"{out.name}.task.yaml"
    task_file.write_text(yaml.safe_dump(doc))
    written: dict[str, list[np.ndarray]] = {}
    add = LeRobotWriter.add

    def spy(self, ep):  # what the writer is handed, episode by episode
        for key, arr in (("state", ep.state), ("action", ep.action), ("depth", ep.depth["wrist"]),
                         ("scene", ep.images["scene"]), ("wrist", ep.images["wrist"])):
            written.setdefault(key, []).append(np.asarray(arr))
        return add(self, ep)

    LeRobotWriter.add = spy  # type: ignore[method-assign]
    task = load_task(task_file)
    sink = DatasetSink(out, "lerobot", task, fps=10, keep="all", language=pick_place_instruction(task.config.pick_place),
                       extra_info={"task_path": str(task_file), "seed": 0, "arm": None, "robot_override": None},
                       limits=FileLimits(chunk_files, data_mb, video_mb))
    report, _ = run_pick_place(task, episodes, seed=0, sink=sink)
    sink.close()
    np.savez_compressed(out.parent / f"{out.name}.expected.npz", **{k: np.concatenate(v) for k, v in written.items()})
    files = {d: sorted(str(p.relative_to(out)) for p in (out / d).rglob("*") if p.is_file())
             for d in ("data", "videos", "meta/episodes")}
    print(f"{episodes} episodes ({sum(e.success for e in report.episodes)} placed), "
          f"{sum(len(v) for v in written['state'])} frames -> {out}")
    print(json.dumps(files, indent=1))


def check(out: Path) -> None:
    import torch  # noqa: F401  (lerobot's venv)
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    exp = np.load(out.parent / f"{out.name}.expected.npz")
    ds = LeRobotDataset("local/check", root=out, video_backend="pyav")
    print(f"lerobot: episodes {ds.num_episodes}, frames {len(ds)}, fps {ds.fps}; written frames {len(exp['state'])}")
    eps = [ds.meta.episodes[i] for i in range(ds.num_episodes)]
    picks: list[tuple[str, int]] = []
    for series in ("data", "videos/observation.images.scene", "videos/observation.images.wrist"):
        where = [(int(e[f"{series}/chunk_index"]), int(e[f"{series}/file_index"])) for e in eps]
        if (0, 1) not in where:
            sys.exit(f"no episode in the second {series} file: lower the limits")
        for target in sorted({(0, 1), where[-1]}):  # the second file and the last one (a later chunk)
            e = [e for e, w in zip(eps, where, strict=True) if w == target][-1]  # its last episode: not at its start
            a, b = int(e["dataset_from_index"]), int(e["dataset_to_index"])
            name = f"{series} chunk-{target[0]:03d}/file-{target[1]:03d}, episode {e['episode_index']}"
            picks += [(f"{name} frame 0", a), (f"{name} frame {(b - a) // 2}", (a + b) // 2)]
    worst = 0.0
    for what, i in picks:
        item = ds[i]
        ep = int(item["episode_index"])
        row = eps[ep]
        line = [f"[{i}] {what}: data file {row['data/chunk_index']}/{row['data/file_index']}"]
        for key, name in (("observation.state", "state"), ("action", "action"), ("observation.depth.wrist", "depth")):
            got = item[key].numpy()
            same = np.array_equal(got, exp[name][i])
            worst = max(worst, 0.0 if same else 1.0)
            line.append(f"{name} {'==' if same else '!='} written")
        for cam in ("scene", "wrist"):
            key = f"observation.images.{cam}"
            img = item[key].numpy().transpose(1, 2, 0) * 255.0  # (3, H, W) in [0, 1] -> (H, W, 3) levels
            fi = int(item["frame_index"])
            pos = round(row[f"videos/{key}/from_timestamp"] * ds.fps) + fi  # frame number within its video file
            other = {"written": i, "previous": i - 1 if fi > 0 else None,
                     "next": i + 1 if fi + 1 < int(row["length"]) else None,
                     "same time in file-000": pos,  # a loader that ignored the file index
                     "from the file's start": i - pos + fi}  # one that ignored from_timestamp
            # frames written identical to frame i (a still scene) cannot tell a wrong frame apart: left out
            err = {k: float(np.abs(img - exp[cam][j]).mean()) for k, j in other.items()
                   if j is not None and (k == "written" or not np.array_equal(exp[cam][j], exp[cam][i]))}
            ok = err["written"] <= min(err.values()) and all(
                err["written"] < err[k] for k in ("same time in file-000", "from the file's start") if k in err)
            direct = _frame(out / ds.meta.get_video_file_path(ep, key), pos)  # PyAV, the file lerobot chose
            same = int(np.abs(np.round(img) - direct).max())
            ok = ok and same <= 1
            worst = max(worst, 0.0 if ok else 1.0)
            line.append(f"{cam} (video file {row[f'videos/{key}/chunk_index']}/{row[f'videos/{key}/file_index']}, "
                        f"frame {pos} there; max |lerobot - PyAV frame {pos}| {same}) "
                        f"mean |decoded - written| {err['written']:.2f} levels; vs "
                        + ", ".join(f"{k} {v:.1f}" for k, v in err.items() if k != "written")
                        + ("" if ok else " WRONG FRAME"))
        print("; ".join(line))
    print("all match" if worst == 0 else "MISMATCH")
    sys.exit(0 if worst == 0 else 1)


def _frame(path: Path, n: int) -> np.ndarray:
    """Frame ``n`` of an MP4 as (H, W, 3) RGB levels, decoded by PyAV."""
    import av

    with av.open(str(path)) as c:
        for k, f in enumerate(c.decode(video=0)):
            if k == n:
                return f.to_ndarray(format="rgb24").astype(float)
    raise IndexError(f"{path} has no frame {n}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("step", choices=("record", "check"))
    ap.add_argument("out", type=Path, help="the dataset directory (new for record)")
    ap.add_argument("--episodes", type=int, default=8)
    ap.add_argument("--size", type=int, default=32, help="camera width and height (pixels)")
    ap.add_argument("--data-mb", type=float, default=0.9)
    ap.add_argument("--video-mb", type=float, default=0.025)
    ap.add_argument("--chunk-files", type=int, default=2, help="files per chunk directory")
    args = ap.parse_args()
    out = args.out.resolve()
    if args.step == "record":
        record(out, args.episodes, args.size, args.data_mb, args.video_mb, args.chunk_files)
    else:
        check(out)


if __name__ == "__main__":
    main()
