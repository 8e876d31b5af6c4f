"""A robot draft (:class:`robocfg.assets.draft.RobotDraft`) written as the commented robot YAML
that ``robocfg new-robot`` saves: every value with a comment saying where it came from, and
``# CHECK`` on the estimates a person must confirm. Text only; the measuring is in
:mod:`robocfg.assets.draft`.
"""

from __future__ import annotations

from robocfg.assets.draft import RobotDraft


def render_yaml(d: RobotDraft) -> str:
    """The draft as a commented robot YAML (``schema_version: 1``). ``# CHECK`` marks guesses."""

    def vec(v) -> str:
        return "[" + ", ".join(_num(x) for x in v) + "]"

    lines = [
        "# Draft written by `robocfg new-robot`: every value comes from the URDF's structure and geometry.",
        "# Lines marked CHECK are estimates a person must confirm; then run `robocfg validate` and",
        "# `robocfg run gripper|trajectory|pick-place --robot THIS_FILE`.",
        "schema_version: 1",
        f"name: {d.name}",
        f"description: {d.name} (drafted by robocfg new-robot from its URDF)",
        f"urdf: {d.urdf_uri}",
    ]
    if d.package_dirs:
        lines += ["package_dirs:"] + [f"  {k}: {v}" for k, v in d.package_dirs.items()]
    if d.attachments:
        lines.append("attachments:")
        for a in d.attachments:
            lines += [f"  - urdf: {a.urdf}", f"    mount_link: {a.mount_link}", f"    mount_xyz: {vec(a.mount_xyz)}",
                      f"    mount_rpy_deg: {vec(a.mount_rpy_deg)}"]
            lines += [f"    name: {a.name}"] if a.name else []
            lines += [f"    prefix: '{a.prefix}'"] if a.prefix is not None else []
    g = d.gripper
    tcp_note = ("finger-pad midpoint with the gripper closed" if g is not None
                else "tip of the tool's geometry (a suction cup's face)")
    home_note = ("IK pose: tool pointing down over the workspace in front of the robot" if d.home_found
                 else "CHECK: 0 or mid-limits. Choose a pose clear of the table, tool down")
    lines += [
        "fixed_base: true",
        "arms:",
        "  - name: arm",
        "    # Longest serial chain of movable (non-mimic) joints, base to tip.",
        f"    joints: [{', '.join(d.arm_joints)}]",
        f"    base_link: {d.base_link}",
        f"    # CHECK: links rigidly attached to the last arm joint: {', '.join(d.ee_candidates)}",
        f"    ee_link: {d.ee_link}",
        f"    # CHECK: {tcp_note}, along ee_axis, measured as robocfg validate measures it.",
        f"    tcp_offset: {_num(d.tcp_offset)}",
        f"    ee_axis: {d.ee_axis}",
        f"    # Grasp x (approach) = ee +{d.ee_axis}"
        + (f", y (closing) = ee {'+' if g.closing_sign > 0 else '-'}{g.closing_axis}" if g else " (no gripper found: CHECK the rest)")
        + ", z = x × y.",
        f"    R_ee_graspnet: [{', '.join(vec(r) for r in d.R_ee_graspnet)}]",
        f"    # {home_note}.",
        f"    home: {vec(d.home)}",
        f"    home_std: {vec([0.05] * len(d.home))}",
    ]
    if g is not None:
        lines += [
            "    gripper:",
            f"      type: {g.kind}",
            "      # Driven (leader) joints; their <mimic> followers are coupled from the URDF.",
            f"      joints: [{', '.join(g.joints)}]",
            f"      open: {vec(g.open)}",
            f"      closed: {vec(g.closed)}",
            "      # Pad-face gaps measured from the geometry at the open and closed positions.",
            f"      max_width: {_num(g.max_width)}",
            f"      min_width: {_num(g.min_width)}",
            f"      finger_links: [{', '.join(g.finger_links)}]",
        ]
        if g.fixed_jaw_face is not None:
            lines += ["      # The fixed jaw's inner face across the ee_axis line, along the closing direction (m).",
                      f"      fixed_jaw_face: {_num(g.fixed_jaw_face)}"]
        lines += [
            "      # CHECK: about 20 N per pad (the lever to the pads; capped by the URDF effort).",
            f"      max_force: {_num(g.max_force)}",
        ]
        if g.max_velocity is not None:
            lines += ["      # The URDF's velocity limit: without it the drive asks for more speed than the joint's",
                      "      # damping lets max_force reach, and the jaws stall part-way.",
                      f"      max_velocity: {_num(g.max_velocity)}"]
        lines += [
            "      lateral_friction: 1.0",
            "    collision_filter:",
            f"      ignore_links: [{', '.join(g.finger_links)}]",
        ]
    else:
        lines += ["    # CHECK: no gripper joints found. For a suction cup:",
                  f"    # gripper: {{type: suction, link: {d.suction_link or 'CUP_LINK'}, hold_force: 50.0}}"]
    lines += [
        "drives:",
        "  # CHECK: PyBullet position-drive gains; raise max_force (N·m) for heavy arms.",
        "  arm: {stiffness: 0.1, damping: 1.0, max_force: 200.0}",
        "physics:",
        "  solver_iterations: 150",
        "  self_collision: true",
    ]
    if d.link_masses:
        lines += ["  # CHECK: these links have no <inertial> (PyBullet would make each 1 kg): 0.01 kg with geometry,",
                  "  # 0.001 kg for bare frames.",
                  "  link_masses:"] + [f"    {ln}: {_num(m)}" for ln, m in sorted(d.link_masses.items())]
    lines.append("ik_backend: lm")
    return "\n".join(lines) + "\n"


def _num(v: float) -> str:
    v = float(v)
    if v == 0:
        return "0.0"
    return repr(round(v, 6))
