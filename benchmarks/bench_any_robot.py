"""Robots no one here tuned for, drafted by ``robocfg new-robot`` and run on the default tasks.

    pip install ".[bench]"            # example-robot-data (131 MB): UR10, Kinova Jaco2, Unitree Z1
    python benchmarks/bench_any_robot.py [--episodes 20] [--json out.json]

Cases (URDFs from the example-robot-data wheel; grippers and tools from airo-models and robocfg):

* ``ur10_2f85`` — UR10 (CB3) + Robotiq 2F-85 composed: ``new-robot`` on ``urdf`` + ``attachments``;
* ``jaco2_suction`` — Kinova Jaco2 (continuous joints, a slow arm: 0.6–1.3 rad/s) with robocfg's
  ø40 mm suction tool welded past its fixed fingers; the draft finds no gripper joints and names
  the tool link in a commented ``gripper:`` line, which this script uncomments (the one edit the
  draft's note asks for);
* ``z1`` — Unitree Z1 (one revolute jaw against a fixed jaw): ``new-robot`` on its URDF.

Each draft is validated, then ``run gripper``, ``run pick-place -n EPISODES``, ``run trajectory``
and ``run follow-target`` run with the default tasks, each as its own ``robocfg`` process.
Prints one row per robot and command (exit code, success, failures by phase).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SUCTION_TOOL = ROOT / "robocfg" / "data" / "robots" / "tools" / "suction_cup_40.urdf"


def erd_root() -> Path:
    """The example-robot-data ``robots`` folder of the installed wheel."""
    from importlib.metadata import PackageNotFoundError, distribution

    try:
        dist = distribution("example-robot-data")
    except PackageNotFoundError:
        sys.exit('example-robot-data is not installed: pip install ".[bench]"')
    for f in dist.files or []:
        if str(f).endswith("robots/z1_description/urdf/z1.urdf"):
            return Path(str(dist.locate_file(f))).parents[2]
    sys.exit("example-robot-data has no robots/z1_description (unexpected wheel layout)")


def sources(erd: Path, folder: Path) -> dict[str, Path]:
    """The input of ``new-robot`` for each case (a URDF, or a YAML with urdf + attachments)."""
    ur10 = folder / "ur10_2f85_parts.yaml"
    ur10.write_text(f"urdf: {erd / 'ur_description/urdf/ur10_robot.urdf'}\n"
                    "attachments:\n  - urdf: airo_models://robotiq_2f_85\n    mount_link: tool0\n")
    jaco = folder / "jaco2_suction_parts.yaml"
    jaco.write_text(f"urdf: {erd / 'kinova_description/robots/kinova.urdf'}\n"
                    f"attachments:\n  - urdf: {SUCTION_TOOL}\n    mount_link: j2s6s200_link_6\n"
                    "    mount_xyz: [0.0, 0.0, -0.17]\n    mount_rpy_deg: [180.0, 0.0, 0.0]\n")
    return {"ur10_2f85": ur10, "jaco2_suction": jaco, "z1": erd / "z1_description/urdf/z1.urdf"}


def robocfg(args: list[str], cwd: Path) -> tuple[int, str, float]:
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "robocfg", *args], capture_output=True, text=True, cwd=cwd)
    return p.returncode, (p.stdout + p.stderr).strip(), time.perf_counter() - t0


def use_suction_hint(yaml_path: Path) -> bool:
    """Uncomment the draft's ``# gripper: {type: suction, ...}`` line; False when there is none."""
    text = yaml_path.read_text()
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if line.strip().startswith("# gripper: {type: suction"):
            lines[k] = line.replace("# gripper:", "gripper:")
            yaml_path.write_text("\n".join(lines) + "\n")
            return True
    return False


def _general(reason: str) -> str:
    """A failure reason with its numbers blanked, so episodes failing the same way count once."""
    import re

    return re.sub(r"-?\d+(\.\d+)?", "#", reason or "")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=20)
    ap.add_argument("--json", type=Path, default=None)
    ap.add_argument("--only", default=None, help="Run one case (ur10_2f85, jaco2_suction, z1).")
    args = ap.parse_args()
    erd = erd_root()
    rows: list[dict] = []
    with tempfile.TemporaryDirectory(prefix="robocfg-anyrobot-") as tmp:
        folder = Path(tmp)
        for name, src in sources(erd, folder).items():
            if args.only and name != args.only:
                continue
            out = folder / f"{name}.yaml"
            code, text, wall = robocfg(["new-robot", str(src), "-o", str(out)], folder)
            row = {"robot": name, "new_robot": code, "draft": text.splitlines()[0] if text else "", "draft_s": round(wall, 1)}
            if code == 0 and name == "jaco2_suction":
                row["edit"] = "uncommented the suction gripper line" if use_suction_hint(out) else "no suction hint"
            if code == 0:
                code, text, _ = robocfg(["validate", str(out)], folder)
                row["validate"] = code
                row["validate_warnings"] = [ln for ln in text.splitlines() if "warning:" in ln]
                for cmd in ("gripper", "trajectory", "follow-target"):
                    rep = folder / f"{name}_{cmd}.json"
                    code, text, wall = robocfg(["run", cmd, "--robot", str(out), "-q", "--json", str(rep)], folder)
                    r = json.loads(rep.read_text()) if rep.exists() else {}
                    ok = code == 0 and bool(r.get("success")) and r.get("reached", True) is not False
                    why = r.get("reason") or r.get("unreachable_reason") or (text.splitlines()[-1] if text and not ok else "")
                    row[cmd] = {"exit": code, "ok": ok, "why": f"{r.get('failed_phase') or ''}: {why}".strip(": "),
                                "wall_s": round(wall, 1)}
                rep = folder / f"{name}_pp.json"
                code, text, wall = robocfg(["run", "pick-place", "--robot", str(out), "-n", str(args.episodes), "--json", str(rep), "-q"], folder)
                summary = json.loads(rep.read_text())["summary"] if rep.exists() else {}
                episodes = json.loads(rep.read_text())["episodes"] if rep.exists() else []
                reasons = sorted({f"{e['failed_phase']}: {_general(e['reason'])}" for e in episodes if not e["success"]})
                row["pick_place"] = {"exit": code, "success": f"{summary.get('successes', 0)}/{summary.get('episodes', args.episodes)}",
                                     "failures_by_phase": summary.get("failures_by_phase", {}), "reasons": reasons[:4],
                                     "wall_s": round(wall, 1)}
                row["yaml"] = out.read_text()
            rows.append(row)
            print(json.dumps({k: v for k, v in row.items() if k != "yaml"}, indent=1), flush=True)
    print("\nrobot          | new-robot | validate | gripper | trajectory | follow-target | pick-place")
    for r in rows:
        def ok(key: str, r: dict = r) -> str:
            v = r.get(key)
            return "—" if v is None else ("ok" if v["ok"] else "FAIL")
        pp = r.get("pick_place", {})
        print(f"{r['robot']:<14} | {'ok' if r['new_robot'] == 0 else 'FAIL':<9} | {'ok' if r.get('validate') == 0 else 'FAIL':<8} | "
              f"{ok('gripper'):<7} | {ok('trajectory'):<10} | {ok('follow-target'):<13} | {pp.get('success', '—')} {pp.get('failures_by_phase', '')}")
    for r in rows:
        for key in ("gripper", "trajectory", "follow-target"):
            if key in r and not r[key]["ok"]:
                print(f"  {r['robot']} {key}: {r[key]['why']}")
        for reason in r.get("pick_place", {}).get("reasons", []):
            print(f"  {r['robot']} pick-place: {reason}")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
