"""What every IK backend provides: :class:`IKSolver`.

A backend is registered as a factory ``KinematicModel -> IKSolver`` (see
:mod:`robocfg.kinematics.ik.registry`). Targets are 4x4 world transforms (m); joint values in
rad (or m for prismatic joints).

Two budgets bound a query. ``time_budget`` (s, on ``clock``) is what the IK benchmark measures
with. ``max_total_iter`` counts iterations over the first descent and every restart together;
when it is set, the answer depends only on the inputs and the ``rng`` (not on the machine or its
load), which is how episode runners get the same JSON for the same seed. Every backend must
honour it, and then ignore ``time_budget``: a wall-clock "safety net" would still end a search
early on a loaded machine (a process descheduled for 0.2 s) and change the answer
(``robocfg.kinematics.ik.common.search`` does this for the backends built on it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    import numpy as np

    from robocfg.kinematics.ik.result import IKResult


class IKSolver(Protocol):
    """One IK backend bound to one kinematic model."""

    name: str
    clock: Callable[[], float]  # what ``time_budget`` is measured with (perf_counter; thread_time for CPU)
    max_total_iter: int | None  # iterations over all restarts; None: bounded by ``time_budget`` only

    def solve(self, target: np.ndarray, seed_q: np.ndarray, frame: str = "tcp", time_budget: float = 0.02,
              position_only: bool = False, rng: np.random.Generator | None = None) -> IKResult:
        """Joint values putting ``frame`` at ``target``, from ``seed_q``; restarts draw from ``rng``
        (None: ``default_rng(0)``). Never raises for an unreachable target (``converged=False``)."""
        ...
