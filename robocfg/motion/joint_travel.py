"""The largest joint change between two configurations (rad or m): ``np.max(np.abs(b − a))``
in Python floats. Moves ask it a few times each (has the arm to move, is the direct IK answer
far, does a line's first point jump), right after physics steps, where numpy's reduction
wrappers cost several times the arithmetic."""

from __future__ import annotations

import math

import numpy as np


def joint_travel(a: np.ndarray, b: np.ndarray) -> float:
    """``max |b − a|`` over the joints (NaN when any difference is NaN, as numpy's)."""
    d = (np.asarray(b, dtype=float) - np.asarray(a, dtype=float)).tolist()
    if any(x != x for x in d):
        return math.nan
    return max(map(abs, d))
