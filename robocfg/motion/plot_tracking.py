"""Plot how well a target was followed: position error (mm), orientation error (deg) and, with
obstacles, the clearance (mm) against time, one panel per quantity (matplotlib, Agg).

The errors are drawn on log scales: the start, where the TCP is still travelling to the target
(hundreds of mm), would otherwise flatten the tracking error (a few mm) into the axis. The
settling window the statistics leave out is shaded, and the tolerance is a dashed line.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

FLOOR_MM = 1e-3  # errors are clipped to this on the log axes (a zero has no logarithm)
FLOOR_DEG = 1e-4


@dataclass(frozen=True)
class TrackingSeries:
    """Sampled tracking errors. ``t`` (s); ``position`` (m) and ``orientation`` (rad) errors of the
    TCP to the target; ``clearance`` (m) robot–obstacle distance, ``inf`` without obstacles."""

    t: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    clearance: np.ndarray

    @classmethod
    def from_rows(cls, rows) -> TrackingSeries:
        """From rows (t s, position error m, orientation error rad, clearance m)."""
        a = np.asarray(rows, float).reshape(-1, 4)
        return cls(a[:, 0], a[:, 1], a[:, 2], a[:, 3])


def tracking_figure(s: TrackingSeries, settle_time: float = 0.0, position_tolerance: float | None = None,
                    orientation_tolerance: float | None = None, safety_margin: float | None = None,
                    title: str = ""):
    """The matplotlib Figure: panels position error (mm, log), orientation error (deg, log) and,
    when some clearance is finite, clearance (mm) with the safety margin. Tolerances in m / rad."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with_clearance = bool(np.isfinite(s.clearance).any())
    n = 3 if with_clearance else 2
    fig, axes = plt.subplots(n, 1, figsize=(8, 2.3 * n + 0.6), sharex=True, squeeze=False)
    axes = axes[:, 0]
    pos_ax, rot_ax = axes[0], axes[1]
    pos_ax.plot(s.t, np.maximum(s.position * 1000, FLOOR_MM), color="tab:blue", lw=1.2, label="position error")
    rot_ax.plot(s.t, np.maximum(np.degrees(s.orientation), FLOOR_DEG), color="tab:orange", lw=1.2,
                label="orientation error")
    if position_tolerance is not None:
        pos_ax.axhline(position_tolerance * 1000, color="tab:green", ls="--", lw=1,
                       label=f"reach tolerance {position_tolerance * 1000:g} mm")
    if orientation_tolerance is not None:
        deg = float(np.degrees(orientation_tolerance))
        rot_ax.axhline(deg, color="tab:green", ls="--", lw=1, label=f"reach tolerance {deg:.2g} deg")
    pos_ax.set_ylabel("position error (mm)")
    rot_ax.set_ylabel("orientation error (deg)")
    for ax in (pos_ax, rot_ax):
        ax.set_yscale("log")
    if with_clearance:
        ax = axes[2]
        ax.plot(s.t, np.where(np.isfinite(s.clearance), s.clearance * 1000, np.nan), color="tab:purple", lw=1.2,
                label="robot–obstacle clearance")
        if safety_margin is not None:
            ax.axhline(safety_margin * 1000, color="tab:red", ls="--", lw=1,
                       label=f"safety margin {safety_margin * 1000:g} mm")
        ax.set_ylabel("clearance (mm)")
    for ax in axes:
        if settle_time > 0:
            ax.axvspan(float(s.t[0]) if len(s.t) else 0.0, settle_time, color="0.85", alpha=0.6,
                       label="settling (not in the statistics)")
        ax.grid(alpha=0.3, which="both")
        ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("t (s)")
    fig.suptitle(title or "target tracking", fontsize=10)
    fig.tight_layout()
    return fig


def plot_tracking(path: str | Path, s: TrackingSeries, **kwargs) -> Path:
    """Write :func:`tracking_figure` as a PNG; returns the path."""
    import matplotlib.pyplot as plt

    fig = tracking_figure(s, **kwargs)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out
