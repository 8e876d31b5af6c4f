"""Reactive target following: a placo QP per control step with collision avoidance.

Public API: :class:`ReactiveController`, :class:`ArmSpec`, :class:`ReactiveSettings`,
:class:`StepResult`, :class:`EnvShape`, :class:`EscapeSettings`; :mod:`.setup` builds the
``ArmSpec`` and environment shapes from a checked robot and a task scene.
Importing this package imports neither placo nor pinocchio; the controller does on construction.
"""

from robocfg.collision import EnvShape
from robocfg.motion.reactive.controller import (
    ArmSpec,
    ReactiveController,
    ReactiveSettings,
    StepResult,
)
from robocfg.motion.reactive.escape import EscapeSettings

__all__ = ["ArmSpec", "EnvShape", "EscapeSettings", "ReactiveController", "ReactiveSettings", "StepResult"]
