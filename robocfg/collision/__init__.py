"""Collision geometry shared by the collision-aware IK (placo) and the reactive controller.

Below both ``kinematics`` and ``motion``: the robot's URDF collision shapes as data
(:func:`robot_geometry`), environment shapes (:class:`EnvShape`), their coal / pinocchio
geometry models (:mod:`.shapes`) and pairwise distances (:class:`DistanceField`). Poses are 4x4
world transforms in metres. Importing this package imports neither coal nor pinocchio; the
functions that build geometry do.
"""

from robocfg.collision.distances import DistanceField, PairDistance
from robocfg.collision.robot import robot_geometry
from robocfg.collision.shapes import EnvShape, LinkGeometry

__all__ = ["DistanceField", "EnvShape", "LinkGeometry", "PairDistance", "robot_geometry"]
