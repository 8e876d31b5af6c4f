"""One command factory for every ``robocfg run <kind>``: the same options, help, progress bar,
output-path checks, exit codes, SIGINT partial report and printing for every registered kind.

The options every kind gets: ``TASK``, ``--robot/-r``, ``--arm``, ``--seed``, ``-n/--episodes``,
``--json``, ``--record``, ``--record-episode``, ``--camera``, ``--size``, ``--fps``, ``--gui``, ``-q``,
``--min-success``, ``--set``. A kind's own
options are the fields of its ``Options`` dataclass (``robocfg.engine.option``). Front-end
additions that need the CLI's own imports are :class:`CliHook` s: the dataset sink of every kind
whose ``Options`` subclass ``DatasetOptions`` (``robocfg.cli.dataset_opts``), and ``HOOKS[kind]``.
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from robocfg.cli.common import GuiOpt, JsonOpt, QuietOpt, RecordOpt, RobotOpt, SeedOpt, _output_path
from robocfg.cli.completion import task_names
from robocfg.cli.executor_opts import ExecutorOpt, RayAddressOpt, WorkersOpt
from robocfg.cli.record_opts import CameraOpt, FpsOpt, SizeOpt, record_settings
from robocfg.cli.set_option import SetOpt

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.engine.options import RunOptions
    from robocfg.engine.runner import TaskCommand, TaskRunner


@dataclass
class CliHook:
    """Front-end work around a kind's run: ``prepare`` may add to the options before the run
    (e.g. a dataset sink), ``finish`` runs after it with the report and returns lines to print."""

    prepare: Callable[[CheckedTask, RunOptions, str | None], RunOptions]
    finish: Callable[[RunOptions, Any], list[str]]


HOOKS: dict[str, CliHook] = {}


def _common_parameters(kind: str, command: str, verb: str, episodic: bool) -> list[inspect.Parameter]:
    def opt(name: str, annotation: Any, default: Any) -> inspect.Parameter:
        return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, annotation=annotation, default=default)

    resume = [opt("resume", Annotated[Path | None, typer.Option(
        "--resume", metavar="REPORT", dir_okay=False,
        help="Finish the interrupted run whose --json report this is: run only its missing episodes and "
             "write the whole report (to --json, else over REPORT). --seed, --arm and -n default to the "
             "report's; anything else that differs is refused.")], None)] if episodic else []
    return [
        opt("task", Annotated[str, typer.Argument(help=f"Task name or YAML path (a 'task: {kind}' file).",
                                                  autocompletion=task_names(kind))], kind),
        opt("robot", RobotOpt, None),
        opt("arm", Annotated[str | None, typer.Option("--arm", help="Arm to use on a multi-arm robot (default: the first).")], None),
        opt("seed", SeedOpt, None),
        opt("episodes", Annotated[int | None, typer.Option("--episodes", "-n", min=1, show_default=False,
                                                           help="Number of seeded episodes (episode k: rng([seed, k])); "
                                                                "default 1.")],
            None),
        opt("json_path", JsonOpt, None),
        opt("record", RecordOpt, None),
        opt("record_episode", Annotated[int, typer.Option("--record-episode", min=0, help="Which episode --record films.")], 0),
        opt("camera", CameraOpt, None),
        opt("size", SizeOpt, None),
        opt("fps", FpsOpt, None),
        opt("gui", GuiOpt, False),
        opt("quiet", QuietOpt, False),
        opt("min_success", Annotated[float, typer.Option("--min-success", min=0.0, max=1.0,
                                                         help=f"Exit 1 when the share of episodes {verb} is below this.")], 1.0),
        opt("set_", SetOpt, None),
        opt("workers", WorkersOpt, None),
        opt("executor", ExecutorOpt, "local"),
        opt("ray_address", RayAddressOpt, None),
        *resume,
    ]


def _kind_parameters(options_type: type | None) -> list[inspect.Parameter]:
    from robocfg.engine.options import option_spec

    if options_type is None:
        return []
    out = []
    for f in dataclasses.fields(options_type):
        spec = option_spec(f)
        kw: dict[str, Any] = {"help": spec.help}
        if spec.output_suffixes:
            suffixes, flag = spec.output_suffixes, spec.flags[0]
            kw.update(parser=_output(suffixes, flag), metavar="PATH")
        if spec.minimum is not None:
            kw.update(min=spec.minimum)
        if spec.choices:
            choices, flag = spec.choices, spec.flags[0]
            kw.update(callback=_choice(choices, flag))
        hint = _resolve(options_type, f.name)
        annotation = Annotated[hint, typer.Option(*spec.flags, **kw)]  # type: ignore[valid-type]
        out.append(inspect.Parameter(f"x_{f.name}", inspect.Parameter.KEYWORD_ONLY, annotation=annotation,
                                     default=f.default))
    return out


def _output(suffixes: tuple[str, ...], option: str) -> Callable[[str], Path]:
    def parse(raw: str) -> Path:
        return _output_path(raw, option, suffixes)

    return parse


def _resolve(cls: type, name: str) -> Any:
    """The type of field ``name`` (annotations may be strings under postponed evaluation)."""
    import typing

    return typing.get_type_hints(cls)[name]


def _choice(choices: tuple[str, ...], option: str) -> Callable[[str], str]:
    def check(value: str) -> str:
        if value not in choices:
            raise typer.BadParameter(f"{value!r}: choose {' or '.join(choices)}", param_hint=option)
        return value

    return check


def make_command(command: type[TaskCommand]) -> Callable[..., int]:
    """The typer command function of a registered kind, from its command face (a built-in kind's
    ``robocfg.runners.<kind>_command`` class, or the runner): the runner loads when it runs."""
    from robocfg.engine.registry import command_name

    name = command_name(command.kind)
    params = _common_parameters(command.kind, name, command.verb, command.episodic) + _kind_parameters(command.Options)

    def run_kind(**kw: Any) -> int:
        from robocfg.engine.registry import runner_for

        runner = runner_for(command.kind)
        extras = None
        if runner.Options is not None:
            extras = runner.Options(**{k[2:]: kw.pop(k) for k in list(kw) if k.startswith("x_")})
        return execute(runner, extras=extras, **kw)

    run_kind.__signature__ = inspect.Signature(params, return_annotation=int)  # type: ignore[attr-defined]
    run_kind.__annotations__ = {p.name: p.annotation for p in params} | {"return": int}
    run_kind.__doc__ = f"{command.summary}\n\n{command.description}" if command.description else command.summary
    run_kind.__name__ = f"run_{command.kind}"
    return run_kind


def execute(runner_type: type[TaskRunner], *, task: str, robot: str | None, arm: str | None, seed: int | None,
            episodes: int | None, json_path: Path | None, record: Path | None, record_episode: int, gui: bool,
            quiet: bool, min_success: float, extras: Any, set_: list[str] | None = None, camera: str | None = None,
            size: str | None = None, fps: float | None = None, workers: int | None = None, executor: str = "local",
            ray_address: str | None = None, resume: Path | None = None) -> int:
    """Check, run, write and print one ``run <kind>``; the exit code (0, 1 or 130). ``episodes``
    None: 1, or with ``resume`` (a partial report) the interrupted run's count."""
    from robocfg.cli.common import console, load_task_for, write_json
    from robocfg.cli.episodes import (
        check_record_episode,
        interrupted_line,
        progress_bar,
        stop_on_signals,
    )
    from robocfg.cli.executor_opts import resolve_workers
    from robocfg.cli.resume import (
        read_partial,
        refuse_with_resume,
        resume_block,
        resume_output,
        resumed_options,
        with_resume_block,
    )
    from robocfg.cli.run_print import print_report
    from robocfg.cli.set_option import overrides
    from robocfg.engine.dataset import DatasetOptions
    from robocfg.engine.options import RunOptions
    from robocfg.engine.registry import command_name
    from robocfg.engine.runner import RunOutput
    from robocfg.errors import PhaseFailed, RunFailed, RunInterrupted
    from robocfg.runners.report_schema import FailedRunReport
    from robocfg.sim.quiet import quiet_import

    kind = runner_type.kind
    partial = read_partial(resume, runner_type) if resume is not None else None
    episodes_given = episodes is not None
    episodes = episodes if episodes is not None else partial.block.episodes if partial is not None else 1
    check_record_episode(record_episode, episodes, record is not None)
    if partial is not None:
        refuse_with_resume(partial, record, record_episode, extras)
        json_path = json_path if json_path is not None else resume_output(partial)
    recording = record_settings(camera, size, fps, record is not None)
    n_workers = resolve_workers(workers, episodes, executor, gui)
    distributed = runner_type.episodic and (n_workers > 1 or executor == "ray")
    quiet_import()
    checked = load_task_for(task, kind, command_name(kind), robot, overrides(set_))
    out = console()
    log = None if quiet or episodes > 1 else (lambda msg: out.print(msg, markup=False))
    options = RunOptions(seed=seed, episodes=episodes, arm=arm, gui=gui, record=record, record_episode=record_episode,
                         recording=recording, extras=extras, log=log)
    if partial is not None:
        options = resumed_options(partial, runner_type, checked, options, episodes_given)
    runner = runner_type(checked, options)
    runner.check()  # exit 2 before anything is simulated
    hook = HOOKS.get(kind)
    if hook is None and runner_type.Options is not None and issubclass(runner_type.Options, DatasetOptions):
        from robocfg.cli.dataset_opts import DATASET_HOOK

        hook = DATASET_HOOK
    if hook is not None:
        runner.options = hook.prepare(checked, runner.options, robot)
    failed: PhaseFailed | None = None
    lost: list[Any] = []
    with stop_on_signals() as stop, \
            progress_bar(command_name(kind), episodes, runner_type.verb, episodes > 1 and not quiet) as tick:
        runner.options = dataclasses.replace(runner.options, on_episode=tick, should_stop=stop)
        for done in runner.options.resumed:  # the bar counts the episodes of the interrupted run too
            if tick is not None:
                tick(done)
        try:
            if distributed:
                from robocfg.cli.parallel import run_distributed

                output, runner.options, lost = run_distributed(checked, runner.options, n_workers, executor,
                                                               ray_address)
            else:
                output = runner.run()
        except PhaseFailed as exc:
            report = exc.report if isinstance(exc, RunFailed) else None
            if report is None:
                if not isinstance(exc, RunInterrupted):  # failed before any report existed (e.g. planning)
                    write_json(json_path, FailedRunReport(kind, str(checked.path), checked.robots[0].config.name,
                                                          exc.phase, exc.reason))
                raise
            failed, output = exc, RunOutput(report)
    extra_lines = hook.finish(runner.options, output.report) if hook is not None else []
    from robocfg.cli.parallel import lost_lines, with_lost

    block = resume_block(runner_type, checked, runner.options) if runner_type.episodic and output.report.interrupted \
        else None
    write_json(json_path, with_resume_block(with_lost(output.report, lost), block))
    print_report(output.report, output.timing, quiet, record, extra_lines)
    for line in lost_lines(lost):
        console(stderr=True).print(line, markup=False)
    if output.report.interrupted:
        console(stderr=True).print(interrupted_line(stop, output.report.episodes_finished(), episodes, json_path),
                                   markup=False)
        return 130
    if failed is not None or lost:
        return 1
    return 0 if output.report.passed(min_success) else 1

