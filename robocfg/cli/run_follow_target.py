"""``robocfg run follow-target [TASK]``: the TCP follows a moving target, avoiding obstacles."""

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
    run_and_report,
)

PlotOpt = Annotated[Path | None, typer.Option("--plot", help="Save a plot (.png) of tracking error and clearance against time.", dir_okay=False)]
WithObstacleOpt = Annotated[bool | None, typer.Option("--with-obstacle/--without-obstacle",
                                                      help="Add the task's follow_target.obstacles (default: the task's with_obstacle).")]


def run_follow_target(
    task: Annotated[str, typer.Argument(help="Task name or YAML path (a 'task: follow_target' file).")] = "follow_target",
    robot: RobotOpt = None,
    with_obstacle: WithObstacleOpt = None,
    gui: GuiOpt = False,
    plot: PlotOpt = None,
    record: RecordOpt = None,
    json_path: JsonOpt = None,
    quiet: QuietOpt = False,
) -> int:
    """Track a static / waypoint / circle / figure-8 target with a QP per control step (placo), keeping
    the safety margin from obstacles, table and ground. With --gui, drag the target with the sliders."""
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.runners.follow_target import run_follow_target as run

    checked = load_task_for(task, "follow_target", "follow-target", robot)
    return run_and_report(lambda: run(checked, gui=gui, with_obstacle=with_obstacle, record=record, plot=plot),
                          json_path, quiet, _print, _one_line)


def _f(v: float | None, unit: str, digits: int = 2) -> str:
    return "—" if v is None else f"{v:.{digits}f} {unit}"


def _one_line(r) -> str:
    e = r.position_error_mm
    track = "no samples after settling" if e is None else f"RMS {e.rms:.2f} mm (max {e.max:.2f})"
    clear = "" if r.min_clearance_mm is None else f", min clearance {r.min_clearance_mm:.1f} mm, {r.contacts} contacts"
    head = "ok" if r.reached else "not reached"
    return (f"{head}: {r.robot} {r.motion} target: {track}, final {r.final_position_error_mm:.2f} mm / "
            f"{r.final_orientation_error_deg:.3f} deg{clear}, step {r.step_time_median_ms:.2f} ms median")


def _print(r) -> None:

    out = console()
    for w in r.warnings:
        out.print(f"[yellow]warning:[/yellow] {w}", markup=True)
    e, o = r.position_error_mm, r.orientation_error_deg

    def stats(s, u: str, d: int) -> str:
        return "—" if s is None else f"mean {s.mean:.{d}f}, RMS {s.rms:.{d}f}, max {s.max:.{d}f} {u}"

    rows = [
        (f"position error (after {r.settle_time:g} s)", stats(e, "mm", 2)),
        (f"orientation error (after {r.settle_time:g} s)", stats(o, "deg", 3)),
        ("final error (residual)", f"{r.final_position_error_mm:.3f} mm / {r.final_orientation_error_deg:.4f} deg"),
        ("reached", "yes" if r.reached else f"no ({r.unreachable_reason})"),
    ]
    if r.obstacles:
        rows += [("obstacles", ", ".join(r.obstacles)),
                 ("min robot–obstacle clearance", f"{_f(r.min_clearance_mm, 'mm')} ({r.min_clearance_link} ↔ "
                                                  f"{r.min_clearance_obstacle}; margin {r.safety_margin * 1000:.0f} mm)"),
                 ("robot–obstacle contacts", f"{r.contacts} ({r.contact_steps} control steps)")]
    rows += [
        ("robot–ground/table contact steps", str(r.environment_contact_steps)),
        ("control step (median / p95)", f"{r.step_time_median_ms:.3f} / {r.step_time_p95_ms:.3f} ms "
                                        f"at {r.control_rate:.0f} Hz, {r.collision_pairs} collision pairs"),
        ("QP relaxed / failed steps", f"{r.soft_steps} / {r.fallback_steps} of {r.steps}"),
        ("local-minimum escapes", str(r.escapes)),
        ("simulated / wall time", f"{r.sim_time:.2f} s / {r.wall_time:.2f} s"),
    ]
    if r.plot:
        rows.append(("plot", r.plot))
    if r.record:
        rows.append(("record", r.record))
    out.print(key_value_table(f"run follow-target: {r.robot} ({r.motion} target, {r.orientation} orientation"
                    f"{', with obstacle' if r.with_obstacle else ''})", rows))
    status = ("[green]ok[/green]" if r.reached else "[yellow]target not reached[/yellow]") if r.success \
        else f"[red]failed[/red]: {r.failed_phase}: {r.reason}"
    out.print(status)
