"""Checks of the joint limits that timed arm moves need (trajectory, pick-place, grasp).

Timing a move (toppra, trapezoids, ruckig) divides by each arm joint's velocity limit, so a joint
with none, from the URDF ``<limit velocity>`` or the robot YAML's ``drives.velocity_limits``,
cannot be timed. Loading a task checks this for the arm that will run, so the problem surfaces in
``validate`` and before ``run`` simulates, not when the first move is planned.
"""

from __future__ import annotations

from collections.abc import Callable

from robocfg.checks.robot import CheckedRobot
from robocfg.errors import Problem


def velocity_limit(robot: CheckedRobot, joint: str) -> float:
    """The velocity limit of ``joint`` (rad/s, or m/s for a prismatic joint): the robot YAML's
    ``drives.velocity_limits`` entry, else the URDF's ``<limit velocity>`` (0 when absent)."""
    return float(robot.config.drives.velocity_limits.get(joint, robot.urdf.joints[joint].velocity))


def missing_velocity_limits(robot: CheckedRobot, joints: list[str] | tuple[str, ...],
                            problem: Callable[[tuple, str], Problem] | None = None) -> list[Problem]:
    """A problem for each of ``joints`` without a velocity limit > 0, located by ``problem(loc,
    message)`` (by default at ``drives.velocity_limits`` of the robot YAML, where the fix goes)."""
    make = problem or robot.doc.problem
    out = []
    for n in joints:
        v = velocity_limit(robot, n)
        if not v > 0:
            out.append(make(("drives", "velocity_limits"),
                            f"joint {n!r} has no velocity limit (URDF <limit velocity> is {robot.urdf.joints[n].velocity:g}); "
                            f"give one in drives.velocity_limits.{n} (rad/s, > 0): timed moves need it"))
    return out
