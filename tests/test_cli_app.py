"""Top-level CLI wiring: --version, --help, unknown commands."""

import subprocess
import sys

from robocfg import __version__


def _run(*args):
    return subprocess.run([sys.executable, "-m", "robocfg", *args], capture_output=True, text=True, timeout=120)


def test_version():
    proc = _run("--version")
    assert proc.returncode == 0 and proc.stdout.strip() == __version__


def test_help_lists_every_command():
    proc = _run("--help")
    assert proc.returncode == 0
    for cmd in ("validate", "robots", "inspect", "new-robot", "schema", "run", "ik", "bench"):
        assert cmd in proc.stdout


def test_unknown_command_is_a_usage_error():
    proc = _run("frobnicate")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
