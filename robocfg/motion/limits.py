"""Joint limits for trajectory timing: positions, velocities, accelerations, optional jerk.

Sources, in order: the URDF ``<limit velocity>``; the robot YAML's ``drives.velocity_limits`` /
``drives.acceleration_limits`` (by joint name) override them; the task's scale factors multiply
them; a joint without an acceleration limit gets the task's default acceleration. Units: rad (or m
for prismatic joints), per s, per s², per s³.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from robocfg.checks.drives import missing_velocity_limits, velocity_limit
from robocfg.errors import ConfigError, Problem


@dataclass(frozen=True)
class JointLimits:
    """Per-joint limits in the order of ``names`` (arrays of shape (n,))."""

    names: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray | None = None
    continuous: np.ndarray | None = None  # bool mask: no position limits

    @property
    def dof(self) -> int:
        return len(self.names)

    def bounded(self) -> np.ndarray:
        """Bool mask of joints with position limits."""
        if self.continuous is None:
            return np.ones(self.dof, dtype=bool)
        return ~self.continuous

    def scaled(self, velocity: float = 1.0, acceleration: float = 1.0, jerk: float = 1.0) -> JointLimits:
        """A copy with the velocity/acceleration/jerk limits multiplied by the given factors."""
        return JointLimits(self.names, self.lower, self.upper, self.velocity * velocity,
                           self.acceleration * acceleration,
                           None if self.jerk is None else self.jerk * jerk, self.continuous)


def make_limits(names: list[str] | tuple[str, ...], lower, upper, velocity, acceleration,
                jerk=None, continuous=None) -> JointLimits:
    """Build and check limits. Raises ValueError naming the joint if a limit is not > 0 and finite."""
    arr = {"velocity": np.asarray(velocity, dtype=float).reshape(-1),
           "acceleration": np.asarray(acceleration, dtype=float).reshape(-1)}
    if jerk is not None:
        arr["jerk"] = np.broadcast_to(np.asarray(jerk, dtype=float), (len(names),)).copy()
    for key, a in arr.items():
        if a.shape != (len(names),):
            raise ValueError(f"{key} limits: {a.size} values for {len(names)} joints")
        for n, v in zip(names, a, strict=True):
            if not np.isfinite(v) or v <= 0:
                raise ValueError(f"{key} limit of {n} is {v:g}; it must be > 0")
    cont = None if continuous is None else np.asarray(continuous, dtype=bool)
    return JointLimits(tuple(names), np.asarray(lower, dtype=float), np.asarray(upper, dtype=float),
                       arr["velocity"], arr["acceleration"], arr.get("jerk"), cont)


def limits_from_robot(robot, joint_names: list[str], params, problem: Callable[[tuple, str], Problem] | None = None) -> JointLimits:
    """Limits of ``joint_names`` for a ``CheckedRobot`` and a task's ``Limits`` block.

    ``problem(loc, message)`` builds a located Problem for the robot YAML (defaults to the robot's
    document). Raises ConfigError for a joint whose velocity limit is missing or not > 0.
    """
    drives = robot.config.drives
    problems = missing_velocity_limits(robot, joint_names, problem)
    if problems:
        raise ConfigError(problems)
    make = problem or robot.doc.problem
    lower, upper, vel, acc, cont = [], [], [], [], []
    for n in joint_names:
        j = robot.urdf.joints[n]
        lower.append(j.lower)
        upper.append(j.upper)
        cont.append(j.type == "continuous")
        vel.append(velocity_limit(robot, n))
        acc.append(drives.acceleration_limits.get(n, params.acceleration))
    try:
        base = make_limits(joint_names, lower, upper, vel, acc, params.jerk, cont)
    except ValueError as exc:  # pragma: no cover - pydantic already forbids these
        raise ConfigError([make(("drives",), str(exc))]) from None
    return base.scaled(params.velocity_scale, params.acceleration_scale)
