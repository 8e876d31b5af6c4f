"""InternDataEngine's new-robot checklist, with the items robocfg verifies by machine marked.

An exported file starts with this block: ``[x]`` items passed robocfg's robot checks (what was
checked is said on the line), ``[!]`` items passed with a warning, ``[ ]`` items are Isaac-side
work robocfg cannot see (USD, physics of the USD, their Python class).
"""

from __future__ import annotations

from robocfg.checks import CheckedRobot
from robocfg.config.robot import ParallelGripperConfig


def checklist_lines(robot: CheckedRobot) -> list[str]:
    """Comment lines: their checklist with robocfg's verdict per item."""
    cfg = robot.config
    parallel = all(isinstance(a.gripper, ParallelGripperConfig) for a in cfg.arms)
    warned = {w.path: w.message for w in robot.warnings}

    def flag(key: str, done: str) -> str:
        hits = [f"{p}: {m}" for p, m in warned.items() if key in p]
        return f"[!] warning: {hits[0]}" if hits else f"[x] {done}"

    tcp_how = ("finger-pad midpoint measured by FK on the finger geometry, open..closed ± 1 cm" if parallel
               else "> 0 (suction tool: no fingers to measure)")
    items = [
        ("Obtain or create robot USD file (URDF → USD via Isaac Sim)", "[ ] Isaac side: convert the URDF named above"),
        ("Verify physics properties (joint movement, damping, stiffness)",
         f"[ ] Isaac side (in PyBullet: `robocfg run gripper --robot {cfg.name}` moves every joint group)"),
        ("Set up collision meshes (use convex hull, not convex decomposition)", "[ ] Isaac side"),
        ("Lock unnecessary joints for dual-arm robots", "[ ] Isaac side"),
        ("Create robot YAML config file", "[x] this file"),
        ("Configure fl_ee_path / fr_ee_path (EE link with fixed EE-to-TCP transform)",
         flag("ee_link", "EE link lies below the arm base and no gripper joint moves it")),
        ("Calculate and set tcp_offset", flag("tcp_offset", f"positive; {tcp_how}")),
        ("Determine ee_axis", flag("ee_axis", "the fingers lie along +ee_axis of the EE link" if parallel
                                   else "one of x, y, z (suction: not measurable)")),
        ("Calculate R_ee_graspnet", flag("R_ee_graspnet", "a rotation (orthonormal, det +1) whose ee_axis column is (1, 0, 0)")),
        ("Configure joint indices", flag("joint", "the movable chain from base to EE, in Isaac DOF order, computed "
                                                  "from the URDF; home within the joint limits")),
        ("Set up gripper keypoints for visualization", flag("keypoints", "in the EE frame; head on the TCP when derived")),
        ("Configure collision filter paths", flag("collision_filter", "every link exists in the URDF")),
        ("Create robot Python class", "[ ] Isaac side"),
        ("Implement _setup_joint_indices() / _setup_paths() / _setup_gripper_keypoints() / _setup_collision_paths()",
         "[ ] Isaac side (the template's versions read the keys below)"),
        ("Implement _get_gripper_state() (1.0 = open, -1.0 = closed)", _gripper_state(robot)),
        ("Register robot in __init__.py", "[ ] Isaac side"),
        ("Add robot to task YAML configuration", "[ ] Isaac side"),
        ("Test robot in simulation", f"[ ] Isaac side (in PyBullet: `robocfg run pick-place --robot {cfg.name}`)"),
    ]
    lines = ["# Checklist (InternDataEngine new-robot guide), as robocfg found it:"]
    for text, verdict in items:
        mark, rest = verdict[:3], verdict[4:]  # "[x] how it was checked"
        lines.append(f"#   {mark} {text}")
        if rest:
            lines.append(f"#       {rest}")
    return lines


def _gripper_state(robot: CheckedRobot) -> str:
    """The threshold robocfg uses (``state_threshold`` of the closed→open travel), as their one-liner."""
    out = []
    for arm in robot.config.arms:
        g = arm.gripper
        if not isinstance(g, ParallelGripperConfig):
            continue
        lo, hi = g.closed[0], g.open[0]
        t = lo + g.state_threshold * (hi - lo)
        op = ">=" if hi > lo else "<="
        out.append(f"{arm.name}: return 1.0 if gripper_home and gripper_home[0] {op} {t:.6g} else -1.0")
    if not out:
        return "[ ] Isaac side (suction tool: robocfg reads the cup's attachment, not a joint)"
    return "[ ] Isaac side; robocfg's rule, as code: " + "; ".join(out)
