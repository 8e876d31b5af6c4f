"""Importing the planning layers does not start the simulator: the grasp planner, the IK
benchmark protocol and the collision geometry load without pybullet, and config models and the
URDF parser load without scipy (so `robocfg validate` stays fast)."""

from __future__ import annotations

import re
import subprocess
import sys


def _loaded_after(imports: list[str], probes: list[str]) -> list[str]:
    code = "; ".join(f"import {m}" for m in imports)
    code += f"; import sys; print(','.join(p for p in {probes!r} if p in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return [p for p in out.stdout.strip().split(",") if p]


def test_planners_do_not_load_pybullet() -> None:
    mods = ["robocfg.grasp.antipodal", "robocfg.grasp.gripper_model", "robocfg.kinematics.ik.bench",
            "robocfg.collision", "robocfg.motion.moves", "robocfg.geometry"]
    assert _loaded_after(mods, ["pybullet"]) == []
    assert _loaded_after(["robocfg.sim.link_boxes"], ["pybullet"]) == ["pybullet"]  # the probe can fail


def test_config_and_urdf_parsing_do_not_load_scipy_or_simulators() -> None:
    mods = ["robocfg.config.robot", "robocfg.config.task", "robocfg.config.types", "robocfg.assets.urdf", "robocfg.assets.urdf_xml",
            "robocfg.geometry"]
    assert _loaded_after(mods, ["scipy", "pybullet", "pinocchio", "placo"]) == []


def test_architecture_doc_lists_the_layers_of_the_contract_in_order() -> None:
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    contracts = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    layers = next(c["layers"] for c in contracts if c["type"] == "layers")
    doc = (root / "docs" / "architecture.md").read_text()
    rows = [line for line in doc.splitlines() if line.startswith("| `robocfg.")]
    for layer in layers:
        for package in (p.strip() for p in layer.split("|")):
            assert any(f"`{package}`" in r for r in rows), f"docs/architecture.md does not list {package}"
    row_of = {pkg: i for i, r in enumerate(rows) for pkg in re.findall(r"`(robocfg\.[a-z_]+)`", r.split("|")[1])}
    order = [row_of[p.strip()] for layer in layers for p in layer.split("|")]
    assert order == sorted(order), "docs/architecture.md lists the layers in another order than pyproject.toml"
