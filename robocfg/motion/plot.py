"""Plot a sampled trajectory: q, q̇, q̈ per joint against time, limits dashed (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def plot_trajectory(path: str | Path, t, q, qd, qdd, names: list[str], limits: dict,
                    waypoint_times: list[float] | None = None, measured: tuple | None = None,
                    title: str = "") -> Path:
    """Write a PNG with one row per joint and columns q (rad), q̇ (rad/s), q̈ (rad/s²).

    ``limits``: dict with per-joint ``lower``, ``upper``, ``velocity``, ``acceleration`` lists;
    drawn as dashed red lines. ``measured``: optional (t, q) from the simulation, drawn over q.
    Waypoint times are dotted grey verticals.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t, q, qd, qdd = (np.asarray(a, dtype=float) for a in (t, q, qd, qdd))
    n = q.shape[1]
    fig, axes = plt.subplots(n, 3, figsize=(13, 1.7 * n + 1.2), sharex=True, squeeze=False)
    cols = [("q (rad)", q, (limits["lower"], limits["upper"])),
            ("q̇ (rad/s)", qd, (-np.asarray(limits["velocity"]), limits["velocity"])),
            ("q̈ (rad/s²)", qdd, (-np.asarray(limits["acceleration"]), limits["acceleration"]))]
    for c, (label, data, (lo, hi)) in enumerate(cols):
        for j in range(n):
            ax = axes[j, c]
            ax.plot(t, data[:, j], color="tab:blue", lw=1.3, label="planned")
            if c == 0 and measured is not None:
                ax.plot(measured[0], np.asarray(measured[1])[:, j], color="tab:orange", lw=0.9, ls="-", label="simulated")
            ax.axhline(float(lo[j]), color="tab:red", ls="--", lw=0.9)
            ax.axhline(float(hi[j]), color="tab:red", ls="--", lw=0.9)
            if c == 0:  # keep the joint range readable: show the limits only if near the motion
                span = float(np.ptp(data[:, j])) or 0.1
                ax.set_ylim(max(float(lo[j]), data[:, j].min() - span) - 0.05 * span,
                            min(float(hi[j]), data[:, j].max() + span) + 0.05 * span)
            for tw in waypoint_times or []:
                ax.axvline(tw, color="0.6", ls=":", lw=0.8)
            if j == 0:
                ax.set_title(label)
            if c == 0:
                ax.set_ylabel(names[j], fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
    for c in range(3):
        axes[-1, c].set_xlabel("t (s)")
    if measured is not None:
        axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle(title or "trajectory (limits dashed, waypoints dotted)", fontsize=10)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out
