"""Plot a sampled trajectory: q, q̇, q̈ per joint against time, limits dashed (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def trajectory_figure(t, q, qd, qdd, names: list[str], limits: dict, waypoint_times: list[float] | None = None,
                      measured: tuple | None = None, title: str = ""):
    """The matplotlib Figure: one row per joint, columns q (rad), q̇ (rad/s), q̈ (rad/s²).

    ``limits``: dict with per-joint ``lower``, ``upper``, ``velocity``, ``acceleration`` lists,
    drawn as dashed red lines; the q panels always span the joint's position limits (shaded beyond
    them), so how close the motion comes to a limit reads at a glance. ``measured``: optional
    (t, q) from the simulation, drawn over q. Waypoint times are dotted grey verticals. Each column's
    first panel has a legend.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t, q, qd, qdd = (np.asarray(a, dtype=float) for a in (t, q, qd, qdd))
    n = q.shape[1]
    fig, axes = plt.subplots(n, 3, figsize=(13, 1.7 * n + 1.2), sharex=True, squeeze=False)
    cols = [("q (rad)", "position limits", q, (limits["lower"], limits["upper"])),
            ("q̇ (rad/s)", "velocity limits", qd, (-np.asarray(limits["velocity"]), limits["velocity"])),
            ("q̈ (rad/s²)", "acceleration limits", qdd, (-np.asarray(limits["acceleration"]), limits["acceleration"]))]
    for c, (label, limit_label, data, (lo, hi)) in enumerate(cols):
        for j in range(n):
            ax = axes[j, c]
            lo_j, hi_j = float(lo[j]), float(hi[j])
            ax.plot(t, data[:, j], color="tab:blue", lw=1.3, label="planned")
            if c == 0 and measured is not None:
                ax.plot(measured[0], np.asarray(measured[1])[:, j], color="tab:orange", lw=0.9, ls="-", label="simulated")
            ax.axhline(lo_j, color="tab:red", ls="--", lw=0.9, label=limit_label)
            ax.axhline(hi_j, color="tab:red", ls="--", lw=0.9)
            if c == 0 and np.isfinite(lo_j) and np.isfinite(hi_j):
                pad = 0.08 * (hi_j - lo_j)
                ax.set_ylim(lo_j - pad, hi_j + pad)
                ax.axhspan(lo_j - pad, lo_j, color="tab:red", alpha=0.12)
                ax.axhspan(hi_j, hi_j + pad, color="tab:red", alpha=0.12)
            for tw in waypoint_times or []:
                ax.axvline(tw, color="0.6", ls=":", lw=0.8)
            if j == 0:
                ax.set_title(label)
                ax.legend(fontsize=7, loc="best")
            if c == 0:
                ax.set_ylabel(names[j], fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    for c in range(3):
        axes[-1, c].set_xlabel("t (s)")
    fig.suptitle(title or "trajectory (limits dashed, waypoints dotted)", fontsize=10)
    fig.tight_layout()
    return fig


def plot_trajectory(path: str | Path, t, q, qd, qdd, names: list[str], limits: dict,
                    waypoint_times: list[float] | None = None, measured: tuple | None = None,
                    title: str = "") -> Path:
    """Write :func:`trajectory_figure` as a PNG; returns the path."""
    import matplotlib.pyplot as plt

    fig = trajectory_figure(t, q, qd, qdd, names, limits, waypoint_times, measured, title)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out
