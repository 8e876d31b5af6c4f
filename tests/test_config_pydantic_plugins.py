"""pydantic's plugin scan spared only when no distribution declares a plugin: the cheap scan agrees
with importlib.metadata, a declared plugin is still loaded and called by pydantic, and without one
robocfg's validation never calls ``entry_points``. Each case runs in a fresh process (pydantic
caches its plugins per process)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from importlib.metadata import entry_points
from pathlib import Path

from robocfg.config.pydantic_plugins import _sections, declares_plugins

ROOT = Path(__file__).resolve().parents[1]


def _python(code: str, *path: Path) -> subprocess.CompletedProcess:
    env_path = ":".join([*map(str, path), str(ROOT)])
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, capture_output=True, text=True,
                          env={"PATH": "/usr/bin:/bin", "PYTHONPATH": env_path})


def test_the_cheap_scan_agrees_with_importlib_metadata() -> None:
    assert declares_plugins() is bool(entry_points(group="pydantic"))


def test_sections_are_read_as_importlib_metadata_reads_them() -> None:
    text = "# comment\n[console_scripts]\nx = a:b\n\n  [ pydantic ]  \np = m:plugin\n[pydantic.other]\n"
    assert _sections(text) == {"console_scripts", "pydantic", "pydantic.other"}


def test_no_plugin_installed_robocfg_validates_without_the_entry_point_scan() -> None:
    out = _python("""
        import importlib.metadata as md
        calls = []
        real = md.entry_points
        md.entry_points = lambda **kw: calls.append(kw) or real(**kw)  # pydantic's loader binds this one
        from robocfg.checks.task import load_task
        from robocfg.config import catalog
        load_task(catalog.find('tasks', 'pick_place'))
        from pydantic.plugin import _loader
        assert _loader._plugins == {} and calls == [], calls
    """)
    assert out.returncode == 0, out.stderr[-2000:]


def test_a_declared_plugin_is_still_loaded_and_called(tmp_path: Path) -> None:
    """A distribution declaring a ``pydantic`` entry point (as ``pip install`` of a plugin leaves it):
    the cheap scan sees it, leaves pydantic to load it, and the plugin sees robocfg's validators."""
    dist = tmp_path / "spy_plugin-1.0.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: spy-plugin\nVersion: 1.0\n")
    (dist / "entry_points.txt").write_text("[pydantic]\nspy = spy_plugin:plugin\n")
    (tmp_path / "spy_plugin.py").write_text(textwrap.dedent("""
        seen = []
        class _Plugin:
            def new_schema_validator(self, schema, schema_type, schema_type_path, schema_kind, config, plugin_settings):
                seen.append(schema_type_path.name)
                return None, None, None
        plugin = _Plugin()
    """))
    out = _python("""
        from robocfg.config.pydantic_plugins import declares_plugins
        assert declares_plugins() is True
        from robocfg.checks.task import load_task
        from robocfg.config import catalog
        load_task(catalog.find('tasks', 'pick_place'))
        import spy_plugin
        assert 'PickPlaceTask' in spy_plugin.seen, spy_plugin.seen
    """, tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
