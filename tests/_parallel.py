"""Helpers of the parallel-run tests: a pick-place task with tiny cameras, a dataset's files,
a CLI run's JSON report."""

from __future__ import annotations

import json
from pathlib import Path

import yaml
from _cli import ROOT, run_main


def small_camera_task(tmp: Path) -> Path:
    """The shipped pick-place task with 32x32 cameras, the wrist one with depth."""
    doc = yaml.safe_load((ROOT / "robocfg/data/tasks/pick_place.yaml").read_text())
    for cam in doc["cameras"]:
        cam["width"] = cam["height"] = 32
    doc["cameras"][1]["depth"] = True
    path = tmp / "pick_place_small_cams.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def files_of(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def run_json(args: list[str], tmp: Path, name: str, capsys, monkeypatch) -> dict:
    out = tmp / f"{name}.json"
    code, _, err = run_main([*args, "--json", str(out), "-q"], capsys, monkeypatch)
    assert code == 0, err
    return json.loads(out.read_text())
