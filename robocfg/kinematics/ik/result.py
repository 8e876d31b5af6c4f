"""The result every IK backend returns."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np


@dataclass
class IKResult:
    """An IK answer.

    ``q``: joint values (arm order, rad or m), the best found even when not converged;
    ``pos_err``: distance (m) between the frame origin at ``q`` and the target;
    ``rot_err``: angle (rad) of the rotation between them (0 in position-only mode);
    ``iterations``: solver iterations over all restarts; ``time_s``: wall time (s);
    ``joints_at_limit``: names of the joints within 1e-6 of a limit (not counting wrapped joints).
    """

    q: np.ndarray
    converged: bool
    pos_err: float
    rot_err: float
    iterations: int
    time_s: float
    joints_at_limit: list[str] = field(default_factory=list)
    backend: str = ""
    restarts: int = 0

    def to_dict(self) -> dict:
        d = asdict(self)
        d["q"] = [float(v) for v in self.q]
        return d
