"""``robocfg run gripper [TASK]``: close/open the gripper, measure widths, test holding an object."""

from __future__ import annotations

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

SAMPLE_EVERY = 0.25  # s between the width samples printed


def gripper(
    task: Annotated[str, typer.Argument(help="Task name or YAML path (a 'task: gripper' file).")] = "gripper",
    robot: RobotOpt = None,
    json_path: JsonOpt = None,
    record: RecordOpt = None,
    gui: GuiOpt = False,
    quiet: QuietOpt = False,
) -> int:
    """Close then open the first arm's gripper; report measured widths, timing, mimic error and the hold test."""
    from robocfg.sim.quiet import quiet_import

    quiet_import()
    from robocfg.runners.gripper import run_gripper

    checked = load_task_for(task, "gripper", "gripper", robot)
    return run_and_report(lambda: run_gripper(checked, gui=gui, record=record), json_path, quiet, _print, _one_line)


def _mm(v: float | None) -> str:
    return "—" if v is None else f"{v * 1000:.1f} mm"


def _s(v: float | None) -> str:
    return "—" if v is None else f"{v:.3f} s"


def _one_line(r) -> str:
    held = "" if r.hold is None else f", {r.hold.object} {'held' if r.hold.held else 'NOT held'}"
    if r.gripper_type != "parallel":
        released = "" if r.hold is None else f", {'released' if r.hold.released else 'NOT released'} when off"
        return f"ok: {r.robot} {r.gripper_type} gripper{held}{released}"
    return (f"ok: {r.robot} {r.gripper_type} gripper closed {_mm(r.final_closed_width)} in {_s(r.time_to_close)}, "
            f"open {_mm(r.final_open_width)} in {_s(r.time_to_open)}{held}")


def _print(r) -> None:
    from rich.table import Table

    out = console()
    for w in r.warnings:
        out.print(f"[yellow]warning:[/yellow] {w}", markup=True)
    rows = [
        ("time to close", _s(r.time_to_close)), ("time to open", _s(r.time_to_open)),
        ("final closed width", _mm(r.final_closed_width)), ("final open width", _mm(r.final_open_width)),
        ("width change", f"{_mm(r.width_change)} of {_mm(r.max_width - r.min_width)} configured"),
        ("mimic tracking error (max)", f"{r.mimic_max_error:.2e}"),
    ]
    if r.hold is not None:
        h = r.hold
        rows += [("hold object", h.object), ("width on object", _mm(h.width_on_object)),
                 ("support lowered by", _mm(h.support_lowered_by) if h.support_lowered_by > 0 else "removed"),
                 ("held", f"{h.held} (sank {_mm(h.drop)}, "
                          f"{'both fingers touching' if r.gripper_type == 'parallel' else 'attached'}: {h.grasping_after})"),
                 ("released on open", str(h.released))]
    rows += [("simulated / wall time", f"{r.sim_time:.2f} s / {r.wall_time:.2f} s")]
    if r.record:
        rows.append(("record", r.record))
    out.print(key_value_table(f"run gripper: {r.robot} ({r.gripper_type}, {r.mode})", rows))
    moves = Table(title="moves")
    for col in ("phase", "cycle", "t start", "width start", "width end", "settled after", "state", "mimic err"):
        moves.add_column(col)
    for m in r.moves:
        moves.add_row(m.phase, str(m.cycle), f"{m.t_start:.2f} s", _mm(m.width_start), _mm(m.width_end),
                      _s(m.settle_time), "open" if m.state_end > 0 else "closed", f"{m.mimic_max_error:.1e}")
    out.print(moves)
    if r.samples and r.samples[0][1] is not None:
        every = max(1, round(SAMPLE_EVERY / r.dt))
        picks = r.samples[::every]
        out.print("width over time: " + "  ".join(f"{t:.2f}s {w * 1000:.1f}" for t, w in picks) + " (mm)")
    status = "[green]ok[/green]" if r.success else f"[red]failed[/red]: {r.failed_phase}: {r.reason}"
    out.print(status)
