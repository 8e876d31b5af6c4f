"""IK backends behind one interface: ``solve(target, seed_q, ...) -> IKResult``.

Backends are looked up by name in :mod:`robocfg.kinematics.ik.registry` (the robot YAML's
``ik_backend``): ``lm`` (Levenberg–Marquardt with random restarts), ``pink`` (differential-IK
QP), ``placo`` (placo's kinematics solver, with self-collision avoidance).
"""

from robocfg.kinematics.ik.registry import get_backend, known_backends, register
from robocfg.kinematics.ik.result import IKResult
from robocfg.kinematics.ik.solver import IKSolver

__all__ = ["IKResult", "IKSolver", "get_backend", "known_backends", "register"]
