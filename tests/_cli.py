"""Run the ``robocfg`` entry point in-process, its error mapping included (shared by CLI tests)."""

import sys
from pathlib import Path

import pytest

from robocfg.cli.app import main

ROOT = Path(__file__).resolve().parent.parent


def run_main(args: list[str], capsys, monkeypatch, cwd: Path = ROOT) -> tuple[int, str, str]:
    """(exit code, stdout, stderr) of ``robocfg ARGS`` run from ``cwd``."""
    monkeypatch.chdir(cwd)
    monkeypatch.delenv("ROBOCFG_DEBUG", raising=False)
    monkeypatch.setattr(sys, "argv", ["robocfg", *args])
    with pytest.raises(SystemExit) as exc:
        main()
    out, err = capsys.readouterr()
    code = exc.value.code
    return (code if isinstance(code, int) else (0 if code is None else 1)), out, err
