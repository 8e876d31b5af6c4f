"""``run <kind> --resume r.json``: finish a batch run that was interrupted.

An interrupted batch run (SIGINT/SIGTERM, report ``"interrupted": true``) writes a ``"resume"``
block into its ``--json`` report: the kind, the episode count asked for, the resolved seed and arm,
and a fingerprint of everything else that decides the episodes' records (the task and robot
configs after ``--robot`` and ``--set``, and the kind's own options). Episodes are independent and
seeded per index, so resuming runs only the missing indices and writes the report an uninterrupted
run would have written. Anything that differs is refused (exit 2) before simulating: a report from
another task, robot, arm, seed or option set cannot be continued.

Options not given again are taken from the report: ``--seed``, ``--arm`` and ``-n``.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from robocfg.errors import ConfigError, Problem

if TYPE_CHECKING:
    from robocfg.checks.task import CheckedTask
    from robocfg.engine.runner import TaskRunner

RESUME_KEY = "resume"


@dataclass(frozen=True)
class ResumeBlock:
    """What an interrupted report carries so that ``--resume`` can check and continue it."""

    kind: str
    robot: str  # the first robot's name
    episodes: int  # episodes the interrupted run was asked for (-n)
    seed: int  # resolved seed (--seed, else the task's sim.seed)
    arm: str  # resolved arm name
    fingerprint: str  # sha256 of the task and robot configs and the kind's options

    def as_json(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class Partial:
    """A partial report read for ``--resume``: its block and the typed records of its episodes."""

    path: Path
    block: ResumeBlock
    records: tuple[Any, ...]


def _problem(path: Path, message: str) -> ConfigError:
    return ConfigError([Problem(f"--resume {path}", None, None, "", message)])


def fingerprint(kind: str, checked: CheckedTask, extras: Any) -> str:
    """sha256 over what decides an episode's record besides seed and arm: the task config (after
    ``--robot`` and ``--set``), the robot configs and the kind's own options."""
    doc = {
        "kind": kind,
        "task": checked.config.model_dump(mode="json"),
        "robots": [r.config.model_dump(mode="json") for r in checked.robots],
        "options": _record_options(extras),
    }
    text = json.dumps(doc, sort_keys=True, default=str)
    return "sha256:" + hashlib.sha256(text.encode()).hexdigest()


def _record_options(extras: Any) -> dict[str, Any] | None:
    """The kind's options that may change its records: all but the files it writes."""
    if not dataclasses.is_dataclass(extras):
        return None
    files = {f.name for f in _path_fields(extras)}
    return {f.name: getattr(extras, f.name) for f in dataclasses.fields(extras) if f.name not in files}


def resume_block(runner_type: type[TaskRunner], checked: CheckedTask, options: Any) -> ResumeBlock:
    """The block this run would write into an interrupted report."""
    robot = checked.robots[0].config
    return ResumeBlock(runner_type.kind, robot.name, options.episodes, options.resolved_seed(checked.config.sim.seed),
                       robot.arm(options.arm).name, fingerprint(runner_type.kind, checked, options.extras))


def read_partial(path: Path, runner_type: type[TaskRunner]) -> Partial:
    """Read and type the partial report at ``path`` (exit 2 naming the problem otherwise)."""
    from robocfg.engine.records import RecordMismatch, episode_record_type, records_from_json
    from robocfg.engine.registry import command_name

    try:
        doc = json.loads(path.read_text())
    except FileNotFoundError:
        raise _problem(path, "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _problem(path, f"cannot be read ({exc.__class__.__name__}: {exc})") from None
    except json.JSONDecodeError as exc:
        raise _problem(path, f"is not JSON (line {exc.lineno}: {exc.msg})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get(RESUME_KEY), dict):
        done = isinstance(doc, dict) and doc.get("interrupted") is False
        raise _problem(path, "is the report of a run that finished: nothing to resume" if done else
                       "is not the report of an interrupted run (it has no 'resume' block)")
    try:
        block = ResumeBlock(**doc[RESUME_KEY])
    except TypeError as exc:
        raise _problem(path, f"has a damaged 'resume' block ({exc})") from None
    if block.kind != runner_type.kind:
        raise _problem(path, f"is a 'run {command_name(block.kind)}' report, not 'run {command_name(runner_type.kind)}'")
    try:
        records = records_from_json(episode_record_type(runner_type.report), doc.get("episodes"))
    except RecordMismatch as exc:
        raise _problem(path, f"episode records do not read back: {exc}") from None
    return Partial(path, block, tuple(records))


def resumed_options(partial: Partial, runner_type: type[TaskRunner], checked: CheckedTask, options: Any,
                    episodes_given: bool) -> Any:
    """``options`` with what was not given taken from the partial report, checked against it,
    and its finished records set as ``resumed`` (exit 2 on any difference)."""
    from robocfg.engine.runner import check_arm_option

    b, path, robot = partial.block, partial.path, checked.robots[0].config
    check_arm_option(robot, options.arm)
    if b.robot != robot.name:
        raise _problem(path, f"is a report of robot {b.robot!r}, this run is of robot {robot.name!r} (--robot)")
    options = dataclasses.replace(
        options,
        seed=b.seed if options.seed is None else options.seed,
        arm=b.arm if options.arm is None else options.arm,
        episodes=options.episodes if episodes_given else b.episodes,
    )
    mine = resume_block(runner_type, checked, options)
    for name, flag in (("seed", "--seed"), ("arm", "--arm")):
        if getattr(mine, name) != getattr(b, name):
            raise _problem(path, f"was run with {flag} {getattr(b, name)}, this run has {flag} {getattr(mine, name)}")
    if mine.fingerprint != b.fingerprint:
        raise _problem(path, "was run with another task or robot (YAML files, --robot, --set) or other options "
                             "of the kind: its episodes cannot be continued here")
    last = max((int(r.index) for r in partial.records), default=-1)
    if last >= options.episodes:
        raise _problem(path, f"holds episode {last}, beyond -n {options.episodes}")
    return dataclasses.replace(options, resumed=partial.records)


def refuse_with_resume(partial: Partial, record: Path | None, record_episode: int, extras: Any) -> None:
    """Outputs a resumed run cannot give: a file of the kind's (a dataset, a cloud) written along
    the interrupted run, and ``--record`` of an episode that already ran."""
    from robocfg.engine.options import option_spec

    for f in _path_fields(extras):
        if getattr(extras, f.name) is not None:
            flag = option_spec(f).flags[0]
            raise ConfigError([Problem(flag, None, None, "", f"cannot be continued by --resume (it would hold only "
                                                             f"the missing episodes): run without {flag}")])
    if record is not None and any(int(r.index) == record_episode for r in partial.records):
        raise ConfigError([Problem("--record-episode", None, None, "",
                                   f"episode {record_episode} finished before the interruption: "
                                   f"--resume runs only the missing episodes")])


def _path_fields(extras: Any) -> list[dataclasses.Field]:
    """The kind's options that name files it writes (typed ``Path`` or ``Path | None``)."""
    import typing

    if not dataclasses.is_dataclass(extras):
        return []
    hints = typing.get_type_hints(type(extras))
    return [f for f in dataclasses.fields(extras)
            if hints[f.name] is Path or Path in typing.get_args(hints[f.name])]


def resume_output(partial: Partial) -> Path:
    """Where the whole report goes without ``--json``: over the partial report, whose folder must
    take a new file (the report is replaced atomically)."""
    from robocfg.cli.common import _can_create_in

    if not _can_create_in(partial.path.parent) or not os.access(partial.path, os.W_OK):
        raise _problem(partial.path, "is not writable (the whole report replaces it): give --json PATH")
    return partial.path


def with_resume_block(payload: Any, block: ResumeBlock | None) -> Any:
    """The JSON payload of an interrupted report: the report plus its ``resume`` block."""
    if block is None:
        return payload
    doc = payload if isinstance(payload, dict) else dataclasses.asdict(payload)
    return doc | {RESUME_KEY: block.as_json()}
