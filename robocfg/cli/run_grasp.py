"""``robocfg run grasp [TASK]``: grasp planning from simulated depth cameras, then lift and shake."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from robocfg.cli.common import (
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


def run_grasp(
    task: Annotated[str, typer.Argument(help="Task name or YAML path (a 'task: grasp' file).")] = "grasp",
    robot: RobotOpt = None,
    arm: Annotated[str | None, typer.Option("--arm", help="Arm to use on a multi-arm robot (default: the first).")] = None,
    episodes: Annotated[int, typer.Option("--episodes", "-n", min=1, help="Episodes (episode k grasps objects[k % n]).")] = 1,
    seed: SeedOpt = None,
    json_path: JsonOpt = None,
    record: RecordOpt = None,
    record_episode: Annotated[int, typer.Option("--record-episode", min=0, help="Which episode --record films.")] = 0,
    save_cloud: Annotated[Path | None, typer.Option("--save-cloud", dir_okay=False,
                                                    help="Write the first object cloud (.npz or .ply).")] = None,
    min_success: Annotated[float, typer.Option("--min-success", min=0.0, max=1.0,
                                               help="Exit 1 when the lift success rate is below this.")] = 1.0,
    quiet: QuietOpt = False,
) -> int:
    """Perceive the object with RGB-D cameras, plan antipodal grasps on the point cloud, execute the
    best (grasp → EE by R_ee_graspnet, ee_axis, tcp_offset), lift, shake and verify; retry the
    next-ranked grasp on failure.

    Exit 0 when the lift success rate reaches --min-success, 1 otherwise (no object points in the
    workspace, no feasible grasp, or the object was not held). --record draws the candidate grasps.
    """
    from robocfg.cli.episodes import (
        check_record_episode,
        interrupted_line,
        progress_bar,
        stop_on_signals,
    )
    from robocfg.errors import ConfigError, Problem, RunFailed
    from robocfg.sim.quiet import quiet_import

    if save_cloud is not None and save_cloud.suffix.lower() not in (".npz", ".ply"):
        raise ConfigError([Problem("--save-cloud", None, None, "", f"needs a .npz or .ply file name, got {save_cloud.name!r}")])
    check_record_episode(record_episode, episodes, record is not None)
    quiet_import()
    from robocfg.runners.grasp import EpisodeFailed
    from robocfg.runners.grasp import run_grasp as run

    checked = load_task_for(task, "grasp", "grasp", robot)
    if not checked.config.grasp.objects:
        raise ConfigError([checked.doc.problem(("grasp", "objects"), "no objects to grasp: give at least one")])
    checked.robots[0].config.arm(arm)  # unknown arm → NotFound before any simulation
    out, err = console(), console(stderr=True)
    recorder = _recorder_factory(record) if record else None
    saver = _cloud_saver(save_cloud) if save_cloud else None
    log = None if quiet or episodes > 1 else (lambda msg: out.print(msg, markup=False))
    try:
        with stop_on_signals() as stop, progress_bar("grasp", episodes, "lifted", episodes > 1 and not quiet) as tick:
            report, timing = run(checked, episodes, seed, arm, recorder, record_episode, log, saver, tick,
                                 should_stop=stop)
    except EpisodeFailed as exc:
        raise RunFailed(exc.phase, exc.reason) from None
    for w in report.warnings:
        err.print(f"warning: {w}", markup=False)
    write_json(json_path, report)
    _print(report, timing, record, save_cloud, quiet)
    if report.interrupted:
        err.print(interrupted_line(stop, len(report.episodes), episodes, json_path), markup=False)
        return 130
    return 0 if report.summary.success_rate >= min_success else 1


def _recorder_factory(path: Path):
    def make(world):
        from robocfg.grasp.draw import GraspRecorder
        from robocfg.sim.record import CameraView

        return GraspRecorder(world, path, fps=12.0, camera=CameraView(target=(0.5, 0.0, 0.08), distance=0.7,
                                                                       yaw_deg=50.0, pitch_deg=-30.0))

    return make


def _cloud_saver(path: Path):
    def save(cloud) -> None:
        from robocfg.grasp.cloud import save_cloud

        save_cloud(cloud, path)

    return save


def _print(report, timing, record, save_cloud, quiet: bool) -> None:
    from robocfg.cli.episodes import failure_lines

    out = console()
    s = report.summary
    failed = [e for e in report.episodes if not e.success]
    if quiet:
        out.print(f"{'ok' if not failed else 'failed'}: {report.robot} lifted {s.successes}/{s.episodes} "
                  f"({s.success_rate:.1%}), planning median {timing.median_planning:.2f} s", markup=False)
        for line in failure_lines(report.episodes):
            out.print(f"  {line}", markup=False)
        return
    rows = [("episodes", str(s.episodes)),
            ("lift success", f"{s.successes}/{s.episodes} ({s.success_rate:.1%}); first attempt {s.first_attempt_rate:.1%}"),
            ("by object", ", ".join(f"{k} {v}" for k, v in s.by_object.items())),
            ("failures by phase", ", ".join(f"{k}: {v}" for k, v in s.failures_by_phase.items()) or "none"),
            ("planning time (median)", f"{timing.median_planning:.3f} s over {len(timing.planning)} plans"),
            ("perception time (median)", f"{timing.median_perception:.3f} s (render + cloud)"),
            ("wall time / episode", f"{sum(timing.per_episode) / max(1, len(timing.per_episode)):.2f} s")]
    if s.episodes == 1:
        e = report.episodes[0]
        rows += [("object points", str(e.object_points)), ("poses evaluated", str(e.poses_evaluated)),
                 ("reachable candidates", str(e.candidates)),
                 ("rejected", ", ".join(f"{k} {v}" for k, v in e.rejected.items() if v) or "none"),
                 ("chosen score", "-" if e.chosen_score is None else f"{e.chosen_score:.3f}"),
                 ("attempts", str(len(e.attempts)))]
    if record:
        rows.append(("record", str(record)))
    if save_cloud:
        rows.append(("cloud", str(save_cloud)))
    out.print(key_value_table(f"run grasp: {report.robot} (arm {report.arm}), seed {report.seed}", rows))
    for line in failure_lines(report.episodes):
        out.print(f"[red]failed[/red] {line}", highlight=False)
    if failed:
        out.print(f"failed episodes: {', '.join(f'{e.index} ({e.object})' for e in failed[:20])}"
                  f"{' ...' if len(failed) > 20 else ''} (seeds and details in --json)")
    if not failed:
        out.print("[green]ok[/green]")
