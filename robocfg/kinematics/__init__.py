"""Kinematics: pinocchio model, FK, Jacobians, IK backends, grasp/TCP frames."""
