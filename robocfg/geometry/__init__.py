"""Rotations and rigid poses, on top of ``scipy.spatial.transform.Rotation``.

The bottom layer of the package: numpy and scipy only, no configuration, no simulator. Every
quaternion / Euler / matrix / pose conversion in robocfg goes through here, so there is one
convention: quaternions are ``(x, y, z, w)`` (scipy's and PyBullet's order), roll-pitch-yaw is
extrinsic X-Y-Z (``R = Rz(yaw)·Ry(pitch)·Rx(roll)``, the URDF and PyBullet convention), poses
are 4x4 homogeneous transforms with positions in metres.
"""

from robocfg.geometry.pose import matrix_to_pose, pose_matrix, pose_to_matrix
from robocfg.geometry.rotation import (
    axis_angle_matrix,
    euler_deg_to_quat_xyzw,
    matrix_to_quat,
    quat_to_matrix,
    rotation_angle,
    rpy_matrix,
)

__all__ = [
    "axis_angle_matrix",
    "euler_deg_to_quat_xyzw",
    "matrix_to_pose",
    "matrix_to_quat",
    "pose_matrix",
    "pose_to_matrix",
    "quat_to_matrix",
    "rotation_angle",
    "rpy_matrix",
]
