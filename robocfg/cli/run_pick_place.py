"""``robocfg run pick-place [TASK]``: the 8-phase pick and place, one or many seeded episodes."""

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
    SeedOpt,
    console,
    key_value_table,
    load_task_for,
    write_json,
)
from robocfg.cli.dataset_opts import (
    DatasetFormatOpt,
    DatasetFpsOpt,
    DatasetOpt,
    KeepOpt,
    dataset_sink,
)


def run_pick_place(
    task: Annotated[str, typer.Argument(help="Task name or YAML path (a 'task: pick_place' file).")] = "pick_place",
    robot: RobotOpt = None,
    arm: Annotated[str | None, typer.Option("--arm", help="Arm to use on a multi-arm robot (default: the first).")] = None,
    episodes: Annotated[int, typer.Option("--episodes", "-n", min=1, help="Number of randomised episodes.")] = 1,
    seed: SeedOpt = None,
    json_path: JsonOpt = None,
    record: RecordOpt = None,
    record_episode: Annotated[int, typer.Option("--record-episode", min=0, help="Which episode --record films.")] = 0,
    min_success: Annotated[float, typer.Option("--min-success", min=0.0, max=1.0,
                                               help="Exit 1 when the success rate is below this.")] = 1.0,
    gui: GuiOpt = False,
    quiet: QuietOpt = False,
    dataset: DatasetOpt = None,
    dataset_format: DatasetFormatOpt = "lerobot",
    dataset_fps: DatasetFpsOpt = 20,
    keep: KeepOpt = "success",
) -> int:
    """Pick the task's object and place it, robot-agnostic (grasp → EE by R_ee_graspnet, ee_axis, tcp_offset).

    Exit 0 when the success rate reaches --min-success (default: every episode), 1 otherwise; the
    --json report (one record per episode; no wall-clock figures, so the same seed gives the same
    file) is written either way. With --dataset every episode is recorded at --dataset-fps
    (observations, the joint-target + gripper actions that drove the robot, phase labels, images of
    the task's cameras) and the kept ones are written as a LeRobot v3.0 or robomimic HDF5 dataset;
    `robocfg dataset replay` re-simulates an episode from those actions.
    """
    from robocfg.cli.episodes import (
        check_record_episode,
        interrupted_line,
        progress_bar,
        stop_on_signals,
    )
    from robocfg.sim.quiet import quiet_import

    check_record_episode(record_episode, episodes, record is not None)
    quiet_import()
    from robocfg.runners.pick_place import run_pick_place as run

    checked = load_task_for(task, "pick_place", "pick-place", robot)
    checked.robots[0].config.arm(arm)  # unknown arm → NotFound before any simulation
    out = console()
    for w in checked.warnings:
        console(stderr=True).print(w.format(), markup=False)
    recorder = _recorder_factory(record) if record else None
    from robocfg.datasets.language import pick_place_instruction

    run_seed = checked.config.sim.seed if seed is None else seed
    sink = dataset_sink(dataset, dataset_format, dataset_fps, keep, checked, run_seed, arm, robot,
                        pick_place_instruction(checked.config.pick_place))
    log = None if quiet or episodes > 1 else (lambda msg: out.print(msg, markup=False))
    with stop_on_signals() as stop, progress_bar("pick-place", episodes, "placed", episodes > 1 and not quiet) as tick:
        report, timing = run(checked, episodes, seed, arm, gui, recorder, record_episode, log, tick, sink=sink,
                             should_stop=stop)
    written = sink.close() if sink is not None else None
    write_json(json_path, report)
    _print(report, timing, record, quiet)
    if written is not None and not quiet:
        out.print(f"dataset ({written.format}): {written.episodes_kept}/{written.episodes_run} episodes kept, "
                  f"{written.frames} frames → {written.path}", markup=False)
    if report.interrupted:
        console(stderr=True).print(interrupted_line(stop, len(report.episodes), episodes, json_path), markup=False)
        return 130
    return 0 if report.summary.success_rate >= min_success else 1


def _recorder_factory(path: Path):
    def make(world):
        from robocfg.sim.record import Recorder

        return Recorder(world, path, fps=12.0)  # camera fitted to the robot, the scene and the place target

    return make


def _print(report, timing, record, quiet: bool) -> None:
    from robocfg.cli.episodes import failure_lines

    out = console()
    s = report.summary
    failed = [e for e in report.episodes if not e.success]
    if quiet:
        out.print(f"{'ok' if not failed else 'failed'}: {report.robot} placed {s.successes}/{s.episodes} "
                  f"({s.success_rate:.1%}), {s.mean_sim_time:.2f} s simulated per episode", markup=False)
        for line in failure_lines(report.episodes):
            out.print(f"  {line}", markup=False)
        return
    rows = [("episodes", str(s.episodes)), ("success", f"{s.successes}/{s.episodes} ({s.success_rate:.1%})"),
            ("failures by phase", ", ".join(f"{k}: {v}" for k, v in s.failures_by_phase.items()) or "none"),
            ("simulated time / episode", f"{s.mean_sim_time:.2f} s"),
            ("wall time / episode", f"{timing.mean_episode:.3f} s (total {timing.wall_time:.1f} s)")]
    if s.episodes == 1:
        e = report.episodes[0]
        rows += [("place error", f"{e.place_error * 100:.2f} cm"), ("tilt", f"{e.tilt_deg:.1f}°")]
    if record:
        rows.append(("record", str(record)))
    out.print(key_value_table(f"run pick-place: {report.robot} (arm {report.arm}), seed {report.seed}", rows))
    for line in failure_lines(report.episodes):
        out.print(f"[red]failed[/red] {line}")
    if failed:
        out.print(f"failed episodes: {', '.join(str(e.index) for e in failed[:20])}"
                  f"{' ...' if len(failed) > 20 else ''} (seeds and details in --json)")
    if not failed:
        out.print("[green]ok[/green]")
