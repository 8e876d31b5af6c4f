"""The generated bad-input corpus (tests/_corpus.py): every case exits 0, or 2 with a
``FILE:LINE[:COL]: FIELD: message`` line; never a traceback or a signal.

Most cases run in-process through the CLI entry point; the ones that used to crash the YAML
library run as subprocesses. Each case's wall time is recorded (``CORPUS_TIMES``, printed with
``-s``), not asserted.
"""

from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
from _cli import ROOT, run_main
from _corpus import Case, all_cases, write

CASES = all_cases()
CORPUS_TIMES: dict[str, float] = {}


def test_corpus_is_large_and_covers_every_kind():
    names = [c.name for c in CASES]
    assert len(CASES) >= 150 and len(set(names)) == len(names)
    for prefix in ("task-valid", "task-bool", "task-typo", "robot-", "urdf-", "cli-", "deep-", "big-", "hold-object", "wp-",
                   "suction-", "velocity-limit-", "variant-", "fixture-", "set-"):
        assert any(n.startswith(prefix) for n in names), prefix
    assert sum(c.exit == 0 for c in CASES) >= 10 and sum(c.exit == 2 for c in CASES) >= 140
    for c in CASES:  # every input `validate` rejects as a parity case is rejected by `run` too
        if c.name.endswith("-validate") and c.exit == 2 and not c.subprocess:
            assert any(d.name == c.name[: -len("validate")] + "run" for d in CASES), c.name


def _check(case: Case, folder: Path, code: int, out: str) -> None:
    assert "Traceback" not in out and "internal error" not in out, out
    assert code == case.exit, f"{case.name}: exit {code}, expected {case.exit}\n{out}"
    if case.exit == 0:
        return
    if case.file is None:  # a command-line error: no file to point at
        assert case.expect in out, out
        return
    where = re.escape(str(folder / case.file)) + r":\d+(?::\d+)?: "
    if case.field is not None:
        where += re.escape(case.field) + ": "
    lines = [ln for ln in out.splitlines() if re.match(where, ln)]
    assert lines, f"{case.name}: no line matching {where!r}\n{out}"
    assert any(case.expect in ln for ln in lines), f"{case.name}: {case.expect!r} not in {lines}"


@pytest.mark.parametrize("case", [c for c in CASES if not c.subprocess], ids=lambda c: c.name)
def test_in_process(case, tmp_path, capsys, monkeypatch):
    args = write(case, tmp_path)
    if case.args[0] == "run" and case.exit == 2:  # rejected before anything is simulated: no world is built
        from robocfg.sim.world import World

        def no_world(*a, **k):
            raise AssertionError(f"{case.name}: a world was built before the run was rejected")
        monkeypatch.setattr(World, "__init__", no_world)
    t0 = time.perf_counter()
    code, out, err = run_main(args, capsys, monkeypatch)
    CORPUS_TIMES[case.name] = time.perf_counter() - t0
    _check(case, tmp_path, code, out + err)


@pytest.mark.parametrize("case", [c for c in CASES if c.subprocess], ids=lambda c: c.name)
def test_subprocess(case, tmp_path):
    args = write(case, tmp_path)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "robocfg", *args], capture_output=True, text=True, cwd=ROOT, timeout=60)
    CORPUS_TIMES[case.name] = time.perf_counter() - t0
    assert proc.returncode >= 0, f"killed by signal {-proc.returncode}"
    _check(case, tmp_path, proc.returncode, proc.stdout + proc.stderr)
