"""robocfg.collector: no garbage collection during a process's start, the collector as before once
its world is built; nothing changes for a program that did not ask. What a process does, not how
fast: benchmarks/bench_startup.py measures the time."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from robocfg import collector, startcache

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def restored() -> Iterator[None]:
    """This test process's collector as it was (thresholds, enabled, nothing frozen by the test)."""
    thresholds, enabled, frozen = gc.get_threshold(), gc.isenabled(), gc.get_freeze_count()
    yield
    if collector.paused():
        collector.resume()
    startcache.uninstall()  # pause() installed the start-up code cache (robocfg.startcache)
    if gc.get_freeze_count() > frozen:
        gc.unfreeze()
    gc.set_threshold(*thresholds)
    (gc.enable if enabled else gc.disable)()


def test_pause_raises_the_threshold_resume_freezes_restore_thaws(restored: None, monkeypatch) -> None:
    monkeypatch.setattr(collector, "nanobind_loaded", lambda: False)  # the suite may have loaded OMPL
    if gc.get_freeze_count():
        pytest.skip("this process froze objects itself")
    gc.set_threshold(700, 10, 10)
    gc.enable()
    collector.pause()
    assert collector.paused()
    assert gc.get_threshold() == (collector.START_THRESHOLD, 10, 10)
    collector.pause()  # a second pause keeps the thresholds saved by the first
    kept = [[] for _ in range(10)]
    collector.resume()
    assert not collector.paused()
    assert gc.get_threshold() == (700, 10, 10)
    assert gc.get_freeze_count() >= len(kept)  # what was alive moved to the permanent generation
    collector.restore()
    assert gc.get_freeze_count() == 0


@pytest.mark.skipif(not hasattr(sys, "setdlopenflags"), reason="no dlopen flags on this platform")
@pytest.mark.parametrize("end", ["resume", "restore"])
def test_pause_loads_extensions_with_lazy_binding_until_the_start_ends(restored: None, monkeypatch, end: str) -> None:
    monkeypatch.setattr(collector, "nanobind_loaded", lambda: True)  # nothing frozen by this test
    flags = sys.getdlopenflags()
    gc.enable()
    collector.pause()
    try:
        assert sys.getdlopenflags() & os.RTLD_LAZY and not sys.getdlopenflags() & os.RTLD_NOW
        assert sys.getdlopenflags() & ~(os.RTLD_LAZY | os.RTLD_NOW) == flags & ~(os.RTLD_LAZY | os.RTLD_NOW)
    finally:
        getattr(collector, end)()
    assert sys.getdlopenflags() == flags


def test_nothing_is_frozen_where_a_nanobind_extension_is_loaded(restored: None, monkeypatch) -> None:
    monkeypatch.setattr(collector, "nanobind_loaded", lambda: True)
    frozen = gc.get_freeze_count()
    collector.pause()
    collector.resume()
    assert gc.get_freeze_count() == frozen


def test_resume_without_pause_changes_nothing(restored: None) -> None:
    gc.set_threshold(500, 7, 3)
    frozen = gc.get_freeze_count()
    collector.resume()
    assert gc.get_threshold() == (500, 7, 3)
    assert gc.get_freeze_count() == frozen


def test_restore_puts_the_thresholds_back_without_freezing(restored: None) -> None:
    gc.set_threshold(700, 10, 10)
    collector.pause()
    frozen = gc.get_freeze_count()
    collector.restore()
    assert not collector.paused()
    assert gc.get_threshold() == (700, 10, 10)
    assert gc.get_freeze_count() == frozen


def test_main_called_in_a_process_leaves_its_collector_as_it_was(restored: None) -> None:
    from robocfg.cli.app import main

    gc.set_threshold(600, 9, 8)
    with pytest.raises(SystemExit):
        sys.argv, argv = ["robocfg", "validate", "robocfg/data/robots/panda.yaml"], sys.argv
        try:
            main()
        finally:
            sys.argv = argv
    assert not collector.paused()
    assert gc.get_threshold() == (600, 9, 8)


def test_a_disabled_collector_is_left_disabled(restored: None) -> None:
    gc.disable()
    flags = sys.getdlopenflags()
    collector.pause()
    assert not collector.paused()
    assert not gc.isenabled()
    assert sys.getdlopenflags() == flags  # a pause that does nothing changes nothing


# a process that pauses first (as the command, a pool worker, a Ray actor and bench_startup's child
# do), opens a pick-place session and prints the collections made up to then and its thresholds
_CHILD = """
import gc, sys
from robocfg import collector
collector.pause()
made = []
gc.callbacks.append(lambda phase, info: made.append(info["generation"]) if phase == "stop" else None)
from robocfg.checks.task import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
session = open_session(load_task(catalog.find("tasks", "pick_place")), RunOptions(seed=0, episodes=1))
print("CHILD", len(made), gc.get_threshold(), collector.paused(), gc.get_freeze_count() > 10000,
      sys.getdlopenflags() == __import__("os").RTLD_NOW)
session.close()
"""


def test_a_paused_process_collects_nothing_until_its_world_is_built_then_as_before() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-c", _CHILD], cwd=ROOT, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    line = next(ln for ln in out.stdout.splitlines() if ln.startswith("CHILD"))
    assert line == "CHILD 0 (700, 10, 10) False True True"  # no collection; CPython's default thresholds and dlopen flags back
