"""``robocfg run trajectory [TASK]``: time-optimal joint trajectory through waypoints, tracked in PyBullet."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import (
    GuiOpt,
    JsonOpt,
    QuietOpt,
    RecordOpt,
    RobotOpt,
    console,
    key_value_table,
    load_task_for,
    write_json,
)

PlotOpt = Annotated[Path | None, typer.Option("--plot", help="Write a PNG of q, q̇, q̈ per joint against time (limits dashed).", dir_okay=False)]


def run_trajectory(
    task: Annotated[str, typer.Argument(help="Task name or YAML path (a 'task: trajectory' file).")] = "trajectory",
    robot: RobotOpt = None,
    json_path: JsonOpt = None,
    plot: PlotOpt = None,
    record: RecordOpt = None,
    gui: GuiOpt = False,
    no_sim: Annotated[bool, typer.Option("--no-sim", help="Plan and check only; do not simulate.")] = False,
    quiet: QuietOpt = False,
) -> int:
    """Plan a time-optimal trajectory through the task's waypoints (toppra; trapezoids with
    stop_at_waypoints; ruckig with a jerk limit), check it against the limits at 1 kHz, and track it
    in PyBullet. Prints duration, planning time, violations and tracking error."""
    from robocfg.errors import RunFailed
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.runners.trajectory import run_trajectory as run

    checked = load_task_for(task, "trajectory", "trajectory", robot)
    if record is not None and no_sim:
        raise typer.BadParameter("--record needs the simulation (drop --no-sim)")
    try:
        result = run(checked, gui=gui, record=record, follow=not no_sim)
    except RunFailed as exc:
        if exc.report is not None:
            write_json(json_path, exc.report)
            if not quiet:
                _print(exc.report)
        raise
    if plot is not None:
        _plot(result, plot)
    write_json(json_path, result)
    if quiet:
        for w in result.warnings:
            console(stderr=True).print(f"warning: {w}", markup=False)
        console().print(_one_line(result))
    else:
        _print(result)
    return 0 if result.success else 1


def _plot(r, path: Path) -> None:
    from robocfg.motion.plot import plot_trajectory

    s = r.samples
    measured = (r.measured["t"], r.measured["q"]) if r.measured else None
    title = (f"{r.robot}: {r.method} ({r.path} path), duration {r.duration:.3f} s — "
             "limits dashed, waypoints dotted")
    r.plot = str(plot_trajectory(path, s.t, s.q, s.qd, s.qdd, r.joint_names, r.limits, r.waypoint_times,
                                 measured, title))


def _one_line(r) -> str:
    tr = r.tracking
    track = "" if tr is None else f", tracking RMS {tr['rms']:.2e} rad, final {tr['final']:.2e} rad"
    status = "ok" if r.success else "FAILED"
    return (f"{status}: {r.robot} {len(r.waypoints)} waypoints, {r.method}, duration {r.duration:.3f} s, "
            f"planned in {r.planning_time_ms:.1f} ms, {r.limit_check['total']} limit violations at 1 kHz{track}")


def _print(r) -> None:
    from rich.markup import escape
    from rich.table import Table

    out = console()
    for w in r.warnings:
        out.print(f"[yellow]warning:[/yellow] {escape(w)}", markup=True)
    for n in r.notes:
        out.print(f"note: {n}", markup=False)
    lc = r.limit_check
    rows = [
        ("method", f"{r.method} ({r.path} path" + (f", {r.gridpoints} gridpoints" if r.gridpoints else "") + ")"),
        ("stop at waypoints", str(r.stop_at_waypoints)),
        ("duration", f"{r.duration:.3f} s"),
        ("planning time", f"{r.planning_time_ms:.1f} ms"),
        ("limit violations (1 kHz)", f"{lc['total']} (peak |q̇|/limit {lc['peak_velocity_ratio']:.4f}, "
                                     f"|q̈|/limit {lc['peak_acceleration_ratio']:.4f})"),
    ]
    if r.tracking is not None:
        t = r.tracking
        rows += [("tracking RMS / max", f"{t['rms']:.2e} / {t['max']:.2e} rad (worst joint)"),
                 ("final error", f"{t['final']:.2e} rad at the end, {t['settled']:.2e} rad after {t['settle_time']:.2f} s"),
                 ("simulated / wall time", f"{r.sim_time:.2f} s / {r.wall_time:.2f} s")]
    if r.plot:
        rows.append(("plot", r.plot))
    if r.record:
        rows.append(("record", r.record))
    out.print(key_value_table(f"run trajectory: {r.robot} ({r.arm})", rows))
    wp = Table(title="waypoints")
    for col in ("#", "from", "t (s)", *r.joint_names):
        wp.add_column(col)
    for k, (i, q, tw) in enumerate(zip(r.waypoint_indices, r.waypoints, r.waypoint_times, strict=True)):
        wp.add_row(str(i), r.waypoint_kinds[k], f"{tw:.3f}", *(f"{v:+.3f}" for v in q))
    out.print(wp)
    if r.tracking is not None:
        jt = Table(title="tracking error per joint (rad)")
        for col in ("joint", "v max", "a max", "RMS", "max", "final"):
            jt.add_column(col)
        t = r.tracking
        for k, n in enumerate(r.joint_names):
            jt.add_row(n, f"{r.limits['velocity'][k]:.3f}", f"{r.limits['acceleration'][k]:.2f}",
                       f"{t['rms_per_joint'][k]:.2e}", f"{t['max_per_joint'][k]:.2e}", f"{t['final_per_joint'][k]:.2e}")
        out.print(jt)
    status = "[green]ok[/green]" if r.success else "[red]failed[/red]: limit violations"
    out.print(status)
