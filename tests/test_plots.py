"""Plots of real runs: the follow-target error plot (one axis per quantity, log scales, legends,
units, the settling window and tolerances) and the trajectory plot (position limits in view)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
import yaml

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.motion.plot import trajectory_figure
from robocfg.motion.plot_tracking import TrackingSeries, tracking_figure
from robocfg.runners.follow_target import run_follow_target
from robocfg.runners.trajectory import run_trajectory

ROOT = Path(__file__).resolve().parent.parent


def _legend(ax) -> list[str]:
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def _hlines(ax) -> list[float]:
    """y values of the horizontal lines drawn across the axes (axhline)."""
    out = []
    for line in ax.get_lines():
        x, y = line.get_xdata(), line.get_ydata()
        if len(y) == 2 and y[0] == y[1] and tuple(x) == (0, 1):
            out.append(float(y[0]))
    return out


@pytest.fixture(scope="module")
def obstacle_run(tmp_path_factory):
    """A 2.5 s follow-target run with a ball next to the target (the plot is written too)."""
    tmp = tmp_path_factory.mktemp("ft")
    doc = {"schema_version": 1, "task": "follow_target",
           "robots": [{"robot_config_file": str(ROOT / "robocfg" / "data" / "robots" / "panda.yaml")}],
           "scene": {"ground": True}, "sim": {"timestep": 1 / 240},
           "follow_target": {"motion": {"type": "static", "center": [0.5, 0.3, 0.3]}, "duration": 2.5,
                             "settle_time": 1.0, "with_obstacle": True,
                             "obstacles": [{"name": "ball", "shape": "sphere", "size": [0.04],
                                            "position": [0.4035, 0.15, 0.3935]}]}}
    path = tmp / "ft.yaml"
    path.write_text(yaml.safe_dump(doc))
    res = run_follow_target(load_task(path), plot=tmp / "ft.png")
    return res


def test_follow_target_plot_has_one_axis_per_quantity(obstacle_run):
    res = obstacle_run
    assert res.plot and Path(res.plot).stat().st_size > 10_000
    rows = [(t, p / 1000, np.radians(r), np.inf if c is None else c / 1000) for t, p, r, c in res.samples]
    s = TrackingSeries.from_rows(rows)
    fig = tracking_figure(s, settle_time=res.settle_time, position_tolerance=0.005,
                          orientation_tolerance=0.05, safety_margin=res.safety_margin)
    try:
        pos, rot, clear = fig.axes  # no twin axes: exactly three panels
        assert "(mm)" in pos.get_ylabel() and "(deg)" in rot.get_ylabel() and "(mm)" in clear.get_ylabel()
        assert pos.get_yscale() == rot.get_yscale() == "log" and clear.get_yscale() == "linear"
        assert _legend(pos)[0] == "position error" and "reach tolerance 5 mm" in _legend(pos)
        assert _legend(rot)[0] == "orientation error"
        assert any(lbl.startswith("safety margin") for lbl in _legend(clear))
        assert res.safety_margin * 1000 in _hlines(clear)
        for ax in fig.axes:
            assert "settling (not in the statistics)" in _legend(ax)
        # the log axis shows both the approach (≥ 10 cm away at first) and the settled error (mm)
        lo, hi = pos.get_ylim()
        settled = s.position[s.t > res.settle_time].min() * 1000
        assert lo <= settled and hi >= s.position.max() * 1000
        assert s.position.max() * 1000 / max(settled, 1e-3) > 20
    finally:
        plt.close(fig)


def test_follow_target_plot_without_obstacles_has_two_panels():
    t = np.linspace(0, 2, 50)
    s = TrackingSeries(t, np.r_[np.full(10, 0.2), np.full(40, 0.001)], np.full(50, 0.01), np.full(50, np.inf))
    fig = tracking_figure(s)
    try:
        assert len(fig.axes) == 2
        assert (fig.axes[0].get_lines()[0].get_ydata() > 0).all()  # zeros clipped for the log axis
    finally:
        plt.close(fig)


def test_trajectory_plot_shows_the_position_limits():
    res = run_trajectory(load_task(catalog.find("tasks", "trajectory")), follow=False)
    s, lim = res.samples, res.limits
    fig = trajectory_figure(s.t, s.q, s.qd, s.qdd, res.joint_names, lim, res.waypoint_times)
    try:
        axes = np.array(fig.axes).reshape(len(res.joint_names), 3)
        for j, ax in enumerate(axes[:, 0]):
            lo, hi = ax.get_ylim()
            assert lo < lim["lower"][j] and hi > lim["upper"][j]  # both limits in view
            assert {round(v, 9) for v in _hlines(ax)} >= {round(lim["lower"][j], 9), round(lim["upper"][j], 9)}
        assert _legend(axes[0, 0]) == ["planned", "position limits"]
        assert _legend(axes[0, 1]) == ["planned", "velocity limits"]
        assert _legend(axes[0, 2]) == ["planned", "acceleration limits"]
        assert [ax.get_title() for ax in axes[0]] == ["q (rad)", "q̇ (rad/s)", "q̈ (rad/s²)"]
    finally:
        plt.close(fig)
