"""The commands shown in README.md and docs/*.md work, so the docs cannot go stale silently.

Every ``robocfg`` command line in a fenced block is parsed by the real command tree: the command
exists, its options exist and take the values shown (a renamed option or sub-command fails
here). Blocks marked ``<!-- docs-test: run -->`` are also run, each in its own scratch folder,
command after command, and every command must exit 0. To keep the run short, what a run command repeats is cut, nothing else: ``-n`` /
``--episodes`` become 1, ``bench ik -n`` becomes 5, an animation ``--record`` (.gif/.mp4)
becomes its one-frame ``.png``. A documented command that cannot run here (it serves a browser
viewer, or needs the reader's own files) belongs in an unmarked block.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import typer.main
from _cli import run_main
from _doc_commands import ROOT, DocCommand, doc_commands

from robocfg.cli.app import app

COMMANDS = doc_commands()
_ROOT_COMMAND = typer.main.get_command(app)
RUN = [c for c in COMMANDS if c.run]
RUN_BLOCKS = {(c.file, c.block): [d for d in RUN if (d.file, d.block) == (c.file, c.block)] for c in RUN}


def test_the_docs_show_commands_and_mark_some_to_run():
    assert len(COMMANDS) >= 40
    assert {c.file for c in RUN} >= {"README.md", "docs/coming-from-interndataengine.md"}
    shown = {c.args[:2] for c in RUN}
    for command in (("validate",), ("tasks",), ("run", "pick-place"), ("run", "gripper"), ("bench", "ik")):
        assert any(s[: len(command)] == command for s in shown), command


@pytest.mark.parametrize("command", COMMANDS, ids=str)
def test_documented_command_parses(command: DocCommand, tmp_path, monkeypatch):
    """Parsing checks names, option spellings, value types and counts, and output paths (their
    folder must exist: the scratch folder has the repository's tests/, robocfg/ and an out/)."""
    _scratch(tmp_path, monkeypatch)
    root = _ROOT_COMMAND
    ctx = root.make_context("robocfg", list(command.args))
    cmd, args = root, [*ctx._protected_args, *ctx.args]
    while hasattr(cmd, "commands"):
        assert args, f"{command}: a sub-command is missing"
        name, cmd, args = cmd.resolve_command(ctx, args)
        assert cmd is not None, f"{command}: no command {name!r}"
        ctx = cmd.make_context(name, args, parent=ctx)
        args = [*ctx._protected_args, *ctx.args]
    assert not args, f"{command}: left over {args}"


@pytest.mark.parametrize("block", list(RUN_BLOCKS), ids=lambda b: f"{b[0]}:{b[1]}")
def test_documented_block_runs(block: tuple[str, int], tmp_path, capsys, monkeypatch):
    _scratch(tmp_path, monkeypatch)
    for command in RUN_BLOCKS[block]:
        code, out, err = run_main(_shortened(command.args), capsys, monkeypatch, tmp_path)
        assert code == 0, f"{command} exited {code}\n{out[-2000:]}\n{err[-2000:]}"


def _scratch(folder: Path, monkeypatch) -> None:
    """A folder like a checkout: repository-relative paths in the docs resolve, outputs land in
    the scratch folder, the user's own search path is empty."""
    for name in ("tests", "robocfg"):
        (folder / name).symlink_to(ROOT / name)
    (folder / "out").mkdir()
    monkeypatch.chdir(folder)
    monkeypatch.delenv("ROBOCFG_PATH", raising=False)


def _shortened(args: tuple[str, ...]) -> list[str]:
    out = list(args)
    bench = out[:2] == ["bench", "ik"]
    for i, word in enumerate(out[:-1]):
        if word in ("-n", "--episodes", "--targets"):
            out[i + 1] = "5" if bench else "1"
        if word == "--record" and out[i + 1].endswith((".gif", ".mp4")):
            out[i + 1] = out[i + 1].rsplit(".", 1)[0] + ".png"
    return out
