"""Task waypoints → joint-space waypoints (arm-joint order), with located errors.

Forms (``trajectory.waypoints[i]`` in the task YAML):

* ``home`` — the arm's home;
* a list of values in arm-joint order (rad or m);
* a ``{joint: value}`` map — joints it does not name keep the previous waypoint's value
  (home's for the first waypoint);
* a Cartesian TCP pose ``{position, euler_deg | quat_xyzw | quat_wxyz}`` in the world frame — solved
  by IK seeded with the previous waypoint's joint values, so consecutive solutions stay on one
  branch (continuity).

Every joint-space waypoint must lie within the joint limits (ConfigError naming the waypoint index
and the joint); an unreachable pose raises RunFailed naming the waypoint.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from robocfg.checks.waypoints import PositionLimits, check_within, joint_waypoint
from robocfg.config.types import Pose
from robocfg.errors import ConfigError, Problem, RunFailed
from robocfg.geometry import pose_matrix
from robocfg.motion.limits import JointLimits

if TYPE_CHECKING:
    from robocfg.kinematics.ik.result import IKResult

IK_POS_TOL = 1e-3  # m
IK_ROT_TOL = 1e-2  # rad
IK_JUMP_WARN = 1.5  # rad: an IK answer this far from the previous waypoint (one joint) earns a warning

# problem(loc, message) -> Problem, loc relative to the waypoint list, e.g. (2, "panda_joint4")
ProblemFn = Callable[[tuple, str], Problem]
# ik(world_T_tcp 4x4, seed q) -> the IK answer (q, converged, pos_err m, rot_err rad)
IKFn = Callable[[np.ndarray, np.ndarray], "IKResult"]


@dataclass
class Waypoints:
    """Joint-space waypoints (k, n) and what each came from ('home', 'list', 'map', 'pose')."""

    q: np.ndarray
    kinds: list[str]
    ik_errors: dict[int, tuple[float, float]]  # waypoint → (position m, rotation rad) residual
    warnings: list[str]


def resolve_waypoints(items: list, limits: JointLimits, home: np.ndarray, problem: ProblemFn,
                      ik: IKFn | None = None) -> Waypoints:
    """Turn the task's waypoint entries into joint values. See the module docstring."""
    problems: list[Problem] = []
    rows: list[np.ndarray] = []
    kinds: list[str] = []
    ik_errors: dict[int, tuple[float, float]] = {}
    warnings: list[str] = []
    prev = np.asarray(home, dtype=float)
    position_limits = PositionLimits(limits.names, limits.lower, limits.upper, limits.bounded())
    for i, item in enumerate(items):
        q: np.ndarray | None = None
        if isinstance(item, Pose):
            kinds.append("pose")
            if ik is None:
                problems.append(problem((i,), "Cartesian waypoints need a kinematic model (none available)"))
            elif not problems:
                res = ik(pose_matrix(item), prev)
                ok = bool(res.converged) and res.pos_err <= IK_POS_TOL and res.rot_err <= IK_ROT_TOL
                if not ok:
                    raise RunFailed("waypoints", f"waypoint {i} (TCP pose at {list(item.position)} m) is unreachable: "
                                    f"IK residual {res.pos_err * 1000:.1f} mm, {np.degrees(res.rot_err):.1f}°")
                q = np.asarray(res.q, dtype=float)
                jump = np.abs(q - prev)
                if jump.max() > IK_JUMP_WARN:
                    k = int(np.argmax(jump))
                    warnings.append(f"waypoint {i}: the IK answer moves {limits.names[k]} by {jump[k]:.2f} rad from the "
                                    "previous waypoint (another IK branch?); add an intermediate waypoint if that is not intended")
                ik_errors[i] = (float(res.pos_err), float(res.rot_err))
                check_within(i, q, position_limits, "pose", problem, problems)
        else:
            kind, q = joint_waypoint(i, item, position_limits, home, prev, problem, problems)
            kinds.append(kind)
        if q is None:
            continue
        rows.append(q)
        prev = q
    if problems:
        raise ConfigError(problems)
    return Waypoints(np.array(rows), kinds, ik_errors, warnings)
