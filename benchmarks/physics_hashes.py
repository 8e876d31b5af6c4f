"""The physics of a set of robocfg runs, fingerprinted: a SHA-1 over every body's pose and velocity
and every joint's position and velocity after **every** ``stepSimulation`` call, per run, plus the
SHA-1 of each run's JSON report (timing fields aside) and dataset files. A change meant to cost
less CPU without changing what is simulated must leave every fingerprint as it was.

    python benchmarks/physics_hashes.py --out before.json          # on the code before
    python benchmarks/physics_hashes.py --compare before.json      # on the code after: exit 1 on a difference

Each run is a fresh process (``python -m robocfg run ...``) with ``pybullet.stepSimulation``
wrapped: the hash is taken whatever loop of robocfg steps the world (the bare playback loop
included), without adding a step hook (which would change which loop runs). ``--only a,b``
selects runs by name; ``--list`` prints them.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PP = ["run", "pick-place"]
RUNS: dict[str, list[str]] = {  # name -> robocfg arguments (a JSON report and datasets go to a temp dir)
    "pick_place_panda": [*PP, "pick_place", "-n", "3", "--seed", "3"],
    "pick_place_ur5e": [*PP, "pick_place", "-n", "2", "--seed", "1", "--robot", "ur5e_robotiq_2f85"],
    "pick_place_ur10e": [*PP, "pick_place_ur10e", "-n", "2", "--seed", "2"],
    "pick_place_iiwa_suction": [*PP, "pick_place", "-n", "2", "--seed", "4", "--robot", "kuka_iiwa_suction"],
    "pick_place_xarm6": [*PP, "pick_place", "-n", "2", "--seed", "5", "--robot", "xarm6"],
    "pick_place_dual_arm_lift": [*PP, "pick_place_dual_arm_lift", "-n", "1", "--seed", "0"],
    "pick_place_obstacle": [*PP, "pick_place_obstacle", "-n", "2", "--seed", "0"],
    "pick_place_planned": [*PP, "pick_place_obstacle_planned", "-n", "1", "--seed", "0"],
    "pick_place_bins": [*PP, "pick_place_bins", "-n", "2", "--seed", "0"],
    "pick_place_dataset_lerobot": [*PP, "pick_place", "-n", "2", "--seed", "6", "--dataset", "{tmp}/ds_lerobot",
                                   "--dataset-format", "lerobot"],
    "pick_place_dataset_hdf5": [*PP, "pick_place", "-n", "2", "--seed", "6", "--dataset", "{tmp}/ds_hdf5",
                                "--dataset-format", "hdf5"],
    "pick_place_many": ["run", "pick-place-many", "pick_place_many", "-n", "1", "--seed", "0"],
    "grasp": ["run", "grasp", "grasp", "--seed", "7"],
    "trajectory": ["run", "trajectory", "trajectory"],
    "follow_target": ["run", "follow-target", "follow_target"],
    "gripper": ["run", "gripper", "gripper"],
}

_CHILD = r"""
import atexit, hashlib, json, sys
import pybullet as p
sha, n = hashlib.sha1(), [0]
step = p.stepSimulation

def _state(c):
    out = []
    for i in range(p.getNumBodies(physicsClientId=c)):
        b = p.getBodyUniqueId(i, physicsClientId=c)
        out.append(p.getBasePositionAndOrientation(b, physicsClientId=c))
        out.append(p.getBaseVelocity(b, physicsClientId=c))
        k = p.getNumJoints(b, physicsClientId=c)
        if k:
            out.append([s[:2] for s in p.getJointStates(b, list(range(k)), physicsClientId=c)])
    return repr(out).encode()

def hashed(*a, **k):
    step(*a, **k)
    sha.update(_state(k.get("physicsClientId", a[0] if a else 0)))
    n[0] += 1

p.stepSimulation = hashed
atexit.register(lambda: print("PHYSICS_HASH", json.dumps({"sha1": sha.hexdigest(), "steps": n[0]}), file=sys.stderr))
sys.argv = ["robocfg", *sys.argv[1:]]
from robocfg.cli.app import main
main()
"""

_TIMING_KEYS = {"wall_s", "timing", "elapsed_s", "physics_s", "episodes_per_s", "wall", "cpu_s"}  # and any key with "time" or "cpu"


def _strip(obj):
    if isinstance(obj, dict):
        return {k: _strip(v) for k, v in obj.items()
                if k not in _TIMING_KEYS and "time" not in k.lower() and "cpu" not in k.lower()}
    if isinstance(obj, list):
        return [_strip(v) for v in obj]
    return obj


def _files_hash(folder: Path, tmp: str) -> str | None:
    """SHA-1 of the files under ``folder`` (names and bytes; the checkout's and the temp folder's
    paths masked: compare checkouts at paths of the same length, as binary files may hold them)."""
    if not folder.exists():
        return None
    sha = hashlib.sha1()
    for f in sorted(q for q in folder.rglob("*") if q.is_file()):
        sha.update(str(f.relative_to(folder)).encode())
        sha.update(f.read_bytes().replace(str(ROOT).encode(), b"<root>").replace(tmp.encode(), b"<tmp>"))
    return sha.hexdigest()


def run_one(name: str, args: list[str]) -> dict:
    with tempfile.TemporaryDirectory(prefix="physhash_") as tmp:
        argv = [a.replace("{tmp}", tmp) for a in args] + ["--json", f"{tmp}/r.json", "-q"]
        env = dict(os.environ, PYTHONPATH=f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")
        proc = subprocess.run([sys.executable, "-c", _CHILD, *argv], cwd=ROOT, env=env, capture_output=True, text=True)
        line = next((ln for ln in proc.stderr.splitlines() if ln.startswith("PHYSICS_HASH ")), None)
        if line is None:
            raise SystemExit(f"{name}: no hash (exit {proc.returncode}):\n{proc.stderr[-2000:]}")
        out = json.loads(line.split(" ", 1)[1]) | {"exit": proc.returncode}
        report = Path(tmp, "r.json")
        if report.exists():  # where the checkout and the temp folder are is not part of the result
            text = report.read_text().replace(str(ROOT), "<root>").replace(tmp, "<tmp>")
            out["report_sha1"] = hashlib.sha1(json.dumps(_strip(json.loads(text)), sort_keys=True).encode()).hexdigest()
        for ds in sorted(Path(tmp).glob("ds_*")):
            out[f"{ds.name}_sha1"] = _files_hash(ds, tmp)
        return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", help="write the fingerprints to this JSON file")
    ap.add_argument("--compare", help="compare with fingerprints written by --out; exit 1 on a difference")
    ap.add_argument("--only", default="", help="comma-separated run names")
    ap.add_argument("--list", action="store_true")
    args = ap.parse_args()
    if args.list:
        print("\n".join(f"{k}: robocfg {' '.join(v)}" for k, v in RUNS.items()))
        return
    names = [n for n in args.only.split(",") if n] or list(RUNS)
    want = json.loads(Path(args.compare).read_text()) if args.compare else {}
    got, bad = {}, []
    for name in names:
        got[name] = run_one(name, RUNS[name])
        same = "" if name not in want else ("same" if want[name] == got[name] else "DIFFERENT")
        if same == "DIFFERENT":
            bad.append(name)
        print(f"{name:28s} steps {got[name]['steps']:7d}  exit {got[name]['exit']}  {got[name]['sha1'][:12]}  {same}",
              flush=True)
        if same == "DIFFERENT":
            print(f"    want {want[name]}\n    got  {got[name]}")
    if args.out:
        Path(args.out).write_text(json.dumps(got, indent=1) + "\n")
    if bad:
        raise SystemExit(f"physics or outputs changed: {', '.join(bad)}")


if __name__ == "__main__":
    main()
