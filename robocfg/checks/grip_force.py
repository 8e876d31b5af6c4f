"""Can a parallel gripper hold the pick-place object by friction, and how hard may it be swung?

At the gripper's force limit (``max_force`` on every driven joint, N or N·m) the pads squeeze the
object with a normal force found by virtual work on the URDF's finger kinematics: the driven
joints turning by dq close the pad gap by d(gap), so each pad pushes with
``N = Σ max_force · |dq_j/ds| / |d gap/ds|`` (s: opening fraction) at the gap the object leaves.
On the 2F-85 that is ≈ 10 N per N·m, as measured in the field notes; on a prismatic hand it is
the joint force. Two pads hold up to ``2 · μ · N`` of friction (μ: pad friction × object friction,
as PyBullet combines them); the object needs ``m · (g + a) · SAFETY``. So:

* ``m · g · SAFETY > 2 μ N``: the gripper cannot hold the object at rest — rejected before
  simulating (``validate`` and ``run`` exit 2, naming the numbers);
* otherwise the hand may accelerate the held object by at most ``2 μ N / (m · SAFETY) − g``
  (m/s²), the transport's limit (:meth:`GripBudget.max_acceleration`).

Units: SI (kg, N, m, m/s²).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robocfg.assets.object_shape import object_shape
from robocfg.assets.paths import UnresolvedPath
from robocfg.checks.robot import CheckedRobot
from robocfg.config.load import YamlDocument
from robocfg.config.robot import ArmConfig, ParallelGripperConfig
from robocfg.config.task import PickPlaceTask
from robocfg.errors import Problem
from robocfg.geometry import quat_to_matrix

G = 9.81  # m/s²
SAFETY = 2.0  # friction must carry twice the load (the usual gripper sizing factor)


@dataclass(frozen=True)
class GripBudget:
    """``pad_force`` (N, normal, each pad, at the force limit ``limit``: the gripper's
    ``max_force``, N or N·m per driven joint), ``friction`` (combined μ) and the object's ``mass`` (kg)."""

    pad_force: float
    friction: float
    mass: float
    limit: float

    @property
    def required_force(self) -> float:
        """Normal force (N, each pad) that holds the object at rest with ``SAFETY``."""
        return self.mass * G * SAFETY / (2.0 * self.friction)

    @property
    def holds(self) -> bool:
        return self.pad_force >= self.required_force

    def max_acceleration(self) -> float:
        """Largest acceleration (m/s²) of the hand that the grip still carries with ``SAFETY``
        (≤ 0 when it cannot even hold the object at rest)."""
        return 2.0 * self.friction * self.pad_force / (self.mass * SAFETY) - G


@dataclass(frozen=True)
class PadForce:
    """Normal force (N) each pad exerts at the force limit, against the pad gap (m): ``gaps``
    ascending, ``forces`` at those gaps."""

    gaps: np.ndarray
    forces: np.ndarray

    def at(self, width: float) -> float:
        """The force (N) with the pads ``width`` (m) apart (the curve's ends beyond it)."""
        return float(np.interp(width, self.gaps, self.forces))


def pad_force(robot: CheckedRobot, arm: ArmConfig) -> PadForce | None:
    """Each pad's normal force at the force limit over the gripper's travel, by virtual work on
    the URDF's pad-gap curve; None without finger geometry or travel, or for a suction cup."""
    g = arm.gripper
    curve = robot.pad_gap_curve(arm)
    if curve is None or not isinstance(g, ParallelGripperConfig):
        return None
    s, gaps = curve
    if np.ptp(gaps) < 1e-4:
        return None
    slope = np.abs(np.gradient(gaps, s))  # m of gap per unit of opening fraction
    work = float(np.sum(g.max_force * np.abs(np.asarray(g.open, float) - np.asarray(g.closed, float))))
    keep = slope > 1e-9
    order = np.argsort(gaps[keep])
    return PadForce(gaps[keep][order], (work / slope[keep])[order])


def object_mass(task: PickPlaceTask, base) -> float:
    """The object's mass (kg): the task's, else its URDF's (a mesh object's own inertial)."""
    obj = task.pick_place.object
    if "mass" in obj.model_fields_set:
        return obj.mass
    try:
        file_mass = object_shape(obj, base).file_mass
    except (UnresolvedPath, ValueError):
        file_mass = None
    return obj.mass if file_mass is None else file_mass


def grip_budget(arm: ArmConfig, force: PadForce | None, mass: float, friction: float, width: float) -> GripBudget | None:
    """The grip on an object of ``mass`` (kg) and ``friction`` held ``width`` (m) wide by ``arm``'s
    gripper, whose pad force is ``force``; None when that is unknown (suction, no finger geometry)."""
    g = arm.gripper
    if force is None or not isinstance(g, ParallelGripperConfig):
        return None
    return GripBudget(force.at(width), g.lateral_friction * friction, mass, g.max_force)


def check_grip_force(doc: YamlDocument, task: PickPlaceTask, robot: CheckedRobot, arm: ArmConfig) -> list[Problem]:
    """One error when the gripper at its force limit cannot hold the object (its heaviest
    randomised mass, its lowest randomised friction) by friction; none otherwise."""
    obj = task.pick_place.object
    try:
        shape = object_shape(obj, doc.path.parent)
    except (UnresolvedPath, ValueError):
        return []  # reported by the mesh and fit checks
    rz = task.pick_place.randomize
    mass = object_mass(task, doc.path.parent) * (1 + rz.mass_scale)
    friction = obj.friction * (1 - rz.friction_scale)
    width = shape.min_horizontal_width(quat_to_matrix(obj.quaternion_xyzw()))
    budget = grip_budget(arm, pad_force(robot, arm), mass, friction, width)
    if budget is None or budget.holds:
        return []
    return [doc.problem(("pick_place", "object", "mass"),
                        f"the gripper cannot hold {mass:.3g} kg by friction: at its force limit (max_force "
                        f"{budget.limit:g}) the pads squeeze with {budget.pad_force:.1f} N each at "
                        f"{width * 1000:.0f} mm, and with friction {budget.friction:.2f} they need "
                        f"{budget.required_force:.1f} N (m·g·{SAFETY:g}/(2·μ))")]
