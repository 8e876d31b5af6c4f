"""The InternDataEngine robot YAML (its new-robot template), as a pydantic model.

Their file describes one Isaac Sim robot: a USD, CuRobo configs per arm, Isaac articulation DOF
indices, USD prim paths, and the grasp conventions robocfg shares (``tcp_offset`` along
``ee_axis`` of the EE link, ``R_ee_graspnet`` with its ``ee_axis`` column = grasp x). Single-arm
robots use the ``left_*`` / ``fl_*`` keys only.

The validators here catch the mistakes their guide warns about but leaves to the reader
(a negative ``tcp_offset``, a non-rotation ``R_ee_graspnet``, an ``ee_axis`` that is not the grasp
approach); each message starts with the offending key so the error points at its line. The
checks that need the URDF live in :mod:`robocfg.interop.interndata_import`.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from robocfg.config.types import AXIS_INDEX, FiniteFloat, Frozen, Matrix3, NonNegFloat

ROT_TOL = 1e-6

Keypoint = Annotated[list[FiniteFloat], Field(min_length=4, max_length=4)]


class Keypoints(Frozen):
    """Homogeneous points ``[x, y, z, 1]`` in the EE link frame (m), for their visualisation."""

    tool_head: Keypoint = Field(description="Fingertip point (along the approach direction).")
    tool_tail: Keypoint = Field(description="Gripper base point.")
    tool_side: Keypoint = Field(description="A point on one side, for the width display.")

    @field_validator("tool_head", "tool_tail", "tool_side")
    @classmethod
    def _homogeneous(cls, v: list[float]) -> list[float]:
        if v[3] != 1:
            raise ValueError(f"the 4th value of a keypoint is the homogeneous 1, got {v[3]}")
        return v


class InterndataRobot(Frozen):
    """One InternDataEngine robot YAML (``workflows/simbox/core/configs/robots/*.yaml``)."""

    target_class: str = Field("", description="Their Python robot class (robocfg robots are data: dropped).")
    path: str = Field("", description="USD file relative to their asset root (robocfg uses the URDF: dropped).")
    robot_file: list[str] = Field(default_factory=list, description="CuRobo config per arm (dropped).")
    gripper_max_width: NonNegFloat = Field(0.0, description="Gripper opening (m).")
    gripper_min_width: NonNegFloat = Field(0.0, description="Gripper closing (m).")
    tcp_offset: FiniteFloat = Field(description="EE origin to TCP along ee_axis (m), > 0.")
    solver_position_iteration_count: Annotated[int, Field(ge=1, le=10000)] = Field(128)
    solver_velocity_iteration_count: int = Field(4)
    stabilization_threshold: float = Field(0.005)
    left_joint_indices: list[Annotated[int, Field(ge=0)]] = Field(min_length=1)
    right_joint_indices: list[Annotated[int, Field(ge=0)]] = Field(default_factory=list)
    left_gripper_indices: list[Annotated[int, Field(ge=0)]] = Field(default_factory=list)
    right_gripper_indices: list[Annotated[int, Field(ge=0)]] = Field(default_factory=list)
    lift_indices: list[Annotated[int, Field(ge=0)]] = Field(default_factory=list)
    fl_ee_path: str = Field(min_length=1)
    fr_ee_path: str = ""
    fl_base_path: str = Field(min_length=1)
    fr_base_path: str = ""
    fl_gripper_keypoints: Keypoints | None = None
    fr_gripper_keypoints: Keypoints | None = None
    fl_filter_paths: list[str] | None = None
    fr_filter_paths: list[str] | None = None
    fl_forbid_collision_paths: list[str] | None = None
    fr_forbid_collision_paths: list[str] | None = None
    R_ee_graspnet: Matrix3
    ee_axis: Literal["x", "y", "z"]
    left_joint_home: list[FiniteFloat]
    right_joint_home: list[FiniteFloat] = Field(default_factory=list)
    left_joint_home_std: list[NonNegFloat] = Field(default_factory=list)
    right_joint_home_std: list[NonNegFloat] = Field(default_factory=list)
    left_gripper_home: list[FiniteFloat] = Field(default_factory=list)
    right_gripper_home: list[FiniteFloat] = Field(default_factory=list)
    lift_home: list[FiniteFloat] = Field(default_factory=list)

    @field_validator("tcp_offset")
    @classmethod
    def _positive_tcp(cls, v: float) -> float:
        if v <= 0:
            raise ValueError(f"must be positive (the distance from the EE origin to the TCP), got {v}; "
                             "a negative value usually means ee_axis points away from the fingers: flip the axis, "
                             "or pick the EE link whose +x, +y or +z points at the fingertips")
        return v

    @field_validator("R_ee_graspnet")
    @classmethod
    def _rotation(cls, v: list[list[float]]) -> list[list[float]]:
        R = np.asarray(v, dtype=float)
        dev = float(np.abs(R @ R.T - np.eye(3)).max())
        det = float(np.linalg.det(R))
        if dev > ROT_TOL or abs(det - 1) > ROT_TOL:
            raise ValueError(f"must be a rotation matrix (orthonormal, det +1); R·Rᵀ deviates from I by {dev:.2e}, "
                             f"det = {det:.4f}")
        return v

    @model_validator(mode="after")
    def _shapes(self) -> InterndataRobot:
        R = np.asarray(self.R_ee_graspnet, dtype=float)
        if np.allclose(R @ R.T, np.eye(3), atol=ROT_TOL):
            col = R[:, AXIS_INDEX[self.ee_axis]]
            if not np.allclose(col, [1, 0, 0], atol=ROT_TOL):
                raise ValueError(
                    f"'ee_axis' is {self.ee_axis!r} but column {AXIS_INDEX[self.ee_axis]} of R_ee_graspnet is "
                    f"{np.round(col, 6).tolist()}: the EE approach axis must be the grasp frame's x, so that column "
                    "must be (1, 0, 0); one of ee_axis and R_ee_graspnet is wrong")
        for side in ("left", "right"):
            n = len(getattr(self, f"{side}_joint_indices"))
            for key in (f"{side}_joint_home", f"{side}_joint_home_std"):
                got = len(getattr(self, key))
                if (got or key.endswith("home")) and got != n:
                    raise ValueError(f"'{key}' has {got} values for {n} {side}_joint_indices")
            g = len(getattr(self, f"{side}_gripper_indices"))
            got = len(getattr(self, f"{side}_gripper_home"))
            if got and got != g:
                raise ValueError(f"'{side}_gripper_home' has {got} values for {g} {side}_gripper_indices")
        if len(self.lift_home) not in (0, len(self.lift_indices)):
            raise ValueError(f"'lift_home' has {len(self.lift_home)} values for {len(self.lift_indices)} lift_indices")
        if self.right_joint_indices and not (self.fr_ee_path and self.fr_base_path):
            raise ValueError("'fr_ee_path' and fr_base_path are needed when right_joint_indices is given")
        return self

    @property
    def sides(self) -> list[str]:
        """'left', plus 'right' on a dual-arm robot."""
        return ["left", "right"] if self.right_joint_indices else ["left"]


SIDE_PREFIX = {"left": "fl", "right": "fr"}
