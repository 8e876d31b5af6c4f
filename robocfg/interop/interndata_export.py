"""``robocfg export interndata``: a validated robocfg robot → an InternDataEngine robot YAML.

Their keys carry what they can: arm ``left``/``right`` (a single arm is ``left``), Isaac articulation
DOF indices (breadth-first, :func:`isaac_dof_order`), link names as prim paths (the URDF importer
puts every link directly under the robot prim), the gripper's driven joints with their open
position as ``*_gripper_home``. Values their format holds once (``tcp_offset``, ``ee_axis``,
``R_ee_graspnet``, gripper widths) come from the first arm; an arm that differs keeps its own in
the ``robocfg:`` block (:mod:`robocfg.interop.extension`), with everything else their format has no
key for. A comment block at the top marks their checklist items that robocfg verified.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from robocfg.checks import CheckedRobot
from robocfg.config.robot import ArmConfig, ParallelGripperConfig
from robocfg.config.types import AXIS_INDEX
from robocfg.errors import RobocfgError
from robocfg.interop.checklist import checklist_lines
from robocfg.interop.extension import BLOCK_KEY, rebase_paths
from robocfg.interop.interndata_schema import SIDE_PREFIX
from robocfg.interop.isaac_order import isaac_dof_order

SHARED = ("tcp_offset", "ee_axis", "R_ee_graspnet")
NATIVE_ARM = ("joints", "joint_indices", "base_link", "ee_link", "home", "home_std", "collision_filter", "gripper_keypoints")
NATIVE_GRIPPER = ("joints", "gripper_indices", "open")
SUCTION_SIDE_MARK = 0.02  # m: where a derived tool_side is drawn for a cup, which has no jaw width


@dataclass
class Exported:
    """Their file's text and what the block had to carry."""

    text: str
    block_keys: list[str]  # top-level robocfg fields their format cannot hold


def export_interndata(robot: CheckedRobot, output: Path) -> Exported:
    """Their YAML for ``robot`` (relative paths in the block written for ``output``'s folder)."""
    cfg = robot.config
    if len(cfg.arms) > 2:
        raise RobocfgError(f"{robot.path}: InternDataEngine configs hold one or two arms; this robot has {len(cfg.arms)}")
    isaac = isaac_dof_order(robot.urdf)
    arm0 = cfg.arms[0]
    grippers = [a.gripper for a in cfg.arms if isinstance(a.gripper, ParallelGripperConfig)]
    g0 = grippers[0] if grippers else None
    sides = ["left", "right"]
    arms: list[ArmConfig | None] = [*cfg.arms, *([None] * (2 - len(cfg.arms)))]
    out: dict[str, Any] = {
        "target_class": "".join(w.capitalize() for w in cfg.name.replace("-", "_").split("_")),
        "path": "",
        "robot_file": ["" for _ in cfg.arms],
        "gripper_max_width": g0.max_width if g0 else 0.0,
        "gripper_min_width": g0.min_width if g0 else 0.0,
        "tcp_offset": arm0.tcp_offset,
        "solver_position_iteration_count": cfg.physics.solver_iterations,
        "solver_velocity_iteration_count": 4,
        "stabilization_threshold": 0.005,
    }
    for side, arm in zip(sides, arms, strict=True):
        out[f"{side}_joint_indices"] = [isaac.index(j) for j in robot.arm_joints(arm)] if arm else []
    for side, arm in zip(sides, arms, strict=True):
        out[f"{side}_gripper_indices"] = [isaac.index(j) for j in robot.gripper_joints(arm)] if arm else []
    out["lift_indices"] = []
    for key, attr in (("ee_path", "ee_link"), ("base_path", "base_link")):
        for side, arm in zip(sides, arms, strict=True):
            out[f"{SIDE_PREFIX[side]}_{key}"] = getattr(arm, attr) if arm else ""
    for side, arm in zip(sides, arms, strict=True):
        out[f"{SIDE_PREFIX[side]}_gripper_keypoints"] = _keypoints(arm) if arm else None
    for key, attr in (("filter_paths", "ignore_links"), ("forbid_collision_paths", "forbid_links")):
        for side, arm in zip(sides, arms, strict=True):
            out[f"{SIDE_PREFIX[side]}_{key}"] = list(getattr(arm.collision_filter, attr)) if arm else []
    out["R_ee_graspnet"] = arm0.R_ee_graspnet
    out["ee_axis"] = arm0.ee_axis
    for key, attr in (("joint_home", "home"), ("joint_home_std", "home_std")):
        for side, arm in zip(sides, arms, strict=True):
            out[f"{side}_{key}"] = list(getattr(arm, attr) or []) if arm else []
    for side, arm in zip(sides, arms, strict=True):
        g = arm.gripper if arm else None
        out[f"{side}_gripper_home"] = list(g.open) if isinstance(g, ParallelGripperConfig) else []
    out["lift_home"] = []
    block = rebase_paths(_block(robot, out), robot.path.parent, output.parent)
    text = "\n".join([*_header(robot), *checklist_lines(robot), "", *_render(out)]) + "\n"
    text += "\n# Fields robocfg needs that this format has no key for; InternDataEngine ignores this block.\n"
    text += yaml.safe_dump({BLOCK_KEY: block}, sort_keys=False, default_flow_style=None, width=120, allow_unicode=True)
    return Exported(text, [k for k in block if k != "arms"])


def _keypoints(arm: ArmConfig) -> dict[str, list[float]]:
    """Their homogeneous keypoints; without ours: head at the TCP, tail at the EE origin, side half a
    jaw opening (a suction cup: ``SUCTION_SIDE_MARK``) along the closing axis, which in the EE frame
    is row 1 of R_ee_graspnet (grasp y)."""
    if arm.gripper_keypoints is not None:
        kp = arm.gripper_keypoints
        return {k: [*getattr(kp, k), 1] for k in ("tool_head", "tool_tail", "tool_side")}
    head = np.zeros(3)
    head[AXIS_INDEX[arm.ee_axis]] = arm.tcp_offset
    half = arm.gripper.max_width / 2 if isinstance(arm.gripper, ParallelGripperConfig) else SUCTION_SIDE_MARK
    side = head + half * np.asarray(arm.R_ee_graspnet, float)[1]
    return {"tool_head": [*map(float, head), 1], "tool_tail": [0.0, 0.0, 0.0, 1], "tool_side": [*map(float, side), 1]}


def _block(robot: CheckedRobot, their: dict[str, Any]) -> dict[str, Any]:
    """Our fields minus what their keys already say exactly."""
    cfg = robot.config
    full = cfg.model_dump(mode="json", exclude_defaults=True)
    full.pop("schema_version", None)
    full.pop("name", None)
    full["description"] = cfg.description
    physics = full.get("physics", {})
    physics.pop("solver_iterations", None)
    if not physics:
        full.pop("physics", None)
    default_names = ["arm"] if len(cfg.arms) == 1 else ["left", "right"]
    for i, (arm, dumped) in enumerate(zip(cfg.arms, full["arms"], strict=True)):
        for key in NATIVE_ARM:
            dumped.pop(key, None)
        if arm.gripper_keypoints is None:
            dumped["gripper_keypoints"] = None  # ours had none: the exported ones are only drawn from the TCP
        if dumped.get("name", "arm") == default_names[i]:
            dumped.pop("name", None)
        for key in SHARED:
            if getattr(arm, key) == their[key]:
                dumped.pop(key, None)
            else:
                dumped[key] = getattr(arm, key)
        g = arm.gripper
        if g is not None:
            gd = dumped.setdefault("gripper", {})
            gd["type"] = g.type
            if isinstance(g, ParallelGripperConfig):
                for key in NATIVE_GRIPPER:
                    gd.pop(key, None)
                for key in ("max_width", "min_width"):
                    if getattr(g, key) == their[f"gripper_{key}"]:
                        gd.pop(key, None)
                    else:
                        gd[key] = getattr(g, key)
    if not any(full["arms"]):
        full.pop("arms")
    return full


def _header(robot: CheckedRobot) -> list[str]:
    return [
        "# " + "=" * 77,
        f"# InternDataEngine robot config for {robot.config.name!r}, written by `robocfg export interndata`",
        f"# from {robot.path.name}.",
        "# " + "=" * 77,
        f"# Description: {robot.config.description}" if robot.config.description else "# Description:",
        "# path: convert the robot's URDF to USD with Isaac Sim's URDF Importer and put the USD path here.",
        f"# URDF: {robot.urdf_path}",
        "# robot_file: one CuRobo config per arm (CuRobo generates them from the same URDF).",
        "# Joint indices are Isaac articulation DOF indices (breadth-first over the URDF tree); link names",
        "# are prim paths under the robot prim, as the URDF Importer lays them out.",
        "#",
    ]


SECTIONS = {
    "target_class": "Robot Info",
    "gripper_max_width": "Gripper Parameters",
    "solver_position_iteration_count": "Physics Solver Parameters (velocity count, threshold: template defaults)",
    "left_joint_indices": "Joint Indices (Isaac articulation DOF order)",
    "fl_ee_path": "End-Effector Paths (relative to robot prim path); the EE-to-TCP transform is fixed",
    "fl_gripper_keypoints": "Gripper Keypoints (in EE frame)",
    "fl_filter_paths": "Collision Filter Paths (relative to robot prim path)",
    "R_ee_graspnet": "Pose Processing Parameters",
    "left_joint_home": "Default Joint Home Positions (radians); gripper home = driven joint positions when open",
}


def _render(their: dict[str, Any]) -> list[str]:
    lines: list[str] = []
    for key, value in their.items():
        if key in SECTIONS:
            lines += ["", "# " + "-" * 77, f"# {SECTIONS[key]}", "# " + "-" * 77]
        if isinstance(value, dict):
            lines.append(f"{key}:")
            lines += [f"  {k}: {json.dumps(v)}" for k, v in value.items()]
        else:
            lines.append(f"{key}: {json.dumps(value)}")
    return lines
