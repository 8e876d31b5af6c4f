"""Same seed ⇒ same JSON: a fresh seeded ``run pick-place`` / ``run grasp`` report must equal the
stored golden file (regenerate only for a documented report-schema change, with
``python tests/test_golden_reports.py``)."""

import json
import math
import sys
from pathlib import Path

import pytest
from _cli import ROOT, run_main

GOLDEN = Path(__file__).parent / "golden"
CASES = {
    "pick-place": ["run", "pick-place", "pick_place", "-n", "2", "--seed", "7", "-q"],
    "grasp": ["run", "grasp", "grasp", "--seed", "7", "-q"],
}


def _normalise(report: dict) -> dict:
    """The task path is where the checkout lives, not part of the result."""
    report = dict(report)
    report["task"] = Path(report["task"]).name
    return report


def _assert_same(got, want, where: str = "$") -> None:
    """Exact for strings, ints, bools and structure; floats to 1e-6 (JSON already rounds them)."""
    if isinstance(want, float) or isinstance(got, float):
        assert isinstance(got, int | float) and not isinstance(got, bool), f"{where}: {got!r} != {want!r}"
        assert math.isclose(got, want, rel_tol=1e-6, abs_tol=1e-6), f"{where}: {got!r} != {want!r}"
    elif isinstance(want, dict):
        assert isinstance(got, dict) and list(got) == list(want), f"{where}: keys {list(got)} != {list(want)}"
        for k in want:
            _assert_same(got[k], want[k], f"{where}.{k}")
    elif isinstance(want, list):
        assert isinstance(got, list) and len(got) == len(want), f"{where}: {got!r} != {want!r}"
        for i, (g, w) in enumerate(zip(got, want, strict=True)):
            _assert_same(g, w, f"{where}[{i}]")
    else:
        assert got == want and type(got) is type(want), f"{where}: {got!r} != {want!r}"


@pytest.mark.parametrize("kind", sorted(CASES))
def test_seeded_report_matches_golden(kind, tmp_path, capsys, monkeypatch):
    out = tmp_path / "r.json"
    code, _, err = run_main([*CASES[kind], "--json", str(out)], capsys, monkeypatch)
    assert code == 0, err
    got = _normalise(json.loads(out.read_text()))
    want = json.loads((GOLDEN / f"{kind}.json").read_text())
    _assert_same(got, want)


def test_comparison_catches_a_changed_value():
    want = json.loads((GOLDEN / "pick-place.json").read_text())
    got = json.loads(json.dumps(want))
    got["episodes"][0]["object_final"][0] += 1e-3
    with pytest.raises(AssertionError, match="object_final"):
        _assert_same(got, want)


if __name__ == "__main__":  # regenerate the golden files
    import subprocess

    for kind, args in CASES.items():
        tmp = GOLDEN / f".{kind}.tmp.json"
        subprocess.run([sys.executable, "-c", "from robocfg.cli.app import main; main()", *args, "--json", str(tmp)],
                       cwd=ROOT, check=True)
        (GOLDEN / f"{kind}.json").write_text(json.dumps(_normalise(json.loads(tmp.read_text())), indent=2) + "\n")
        tmp.unlink()
