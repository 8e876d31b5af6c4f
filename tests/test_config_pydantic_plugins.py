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


def _spy_plugin(tmp_path: Path) -> Path:
    """A distribution declaring a ``pydantic`` entry point (as ``pip install`` of a plugin leaves
    it), whose plugin records the validators pydantic builds; its folder (for ``sys.path``)."""
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
    return tmp_path


def test_a_declared_plugin_is_still_loaded_and_called(tmp_path: Path) -> None:
    """The cheap scan sees a declared plugin, leaves pydantic to load it, and the plugin sees
    robocfg's validators."""
    out = _python("""
        from robocfg.config.pydantic_plugins import declares_plugins
        assert declares_plugins() is True
        from robocfg.checks.task import load_task
        from robocfg.config import catalog
        load_task(catalog.find('tasks', 'pick_place'))
        import spy_plugin
        assert 'PickPlaceTask' in spy_plugin.seen, spy_plugin.seen
    """, _spy_plugin(tmp_path))
    assert out.returncode == 0, out.stderr[-2000:]


def test_the_command_defers_importlib_metadata_and_still_calls_a_declared_plugin(tmp_path: Path) -> None:
    """``robocfg validate``: typer's parameter adapters import pydantic's loader before robocfg's
    models do; without a plugin the command still runs without ``importlib.metadata`` and its
    loader's cache is filled; with one, the plugin is loaded and sees robocfg's models."""
    run = """
        import atexit, runpy, sys
        def _check():
            from pydantic.plugin import _loader
            print('METADATA', 'importlib.metadata' in sys.modules, 'PLUGINS', _loader._plugins == {})
            if 'spy_plugin' in sys.modules:
                print('SEEN', sorted(set(sys.modules['spy_plugin'].seen)))
        atexit.register(_check)
        sys.argv = ['robocfg', 'validate', 'robocfg/data/tasks/pick_place.yaml']
        runpy.run_module('robocfg', run_name='__main__')
    """
    plain = _python(run)
    assert plain.returncode == 0, plain.stderr[-2000:]
    assert "METADATA False PLUGINS True" in plain.stdout
    spied = _python(run, _spy_plugin(tmp_path))
    assert spied.returncode == 0, spied.stderr[-2000:]
    assert "METADATA True PLUGINS False" in spied.stdout
    seen = spied.stdout.split("SEEN", 1)[1]
    assert "PickPlaceTask" in seen and "RobotConfig" in seen


def test_validation_leaves_importlib_metadata_unimported_and_the_loader_working() -> None:
    """pydantic's loader is imported with ``importlib.metadata`` deferred: a task validates (its
    validators built) without importing it; the loader's ``entry_points`` then imports the real
    module and answers as its own ``entry_points`` does."""
    out = _python("""
        import sys
        from robocfg.checks.task import load_task
        from robocfg.config import catalog
        load_task(catalog.find('tasks', 'pick_place'))
        from pydantic.plugin import _loader
        assert _loader._plugins == {}, _loader._plugins
        assert 'importlib.metadata' not in sys.modules
        assert list(_loader.get_plugins()) == []
        got = _loader.entry_points(group='console_scripts')
        import importlib.metadata as md
        assert type(sys.modules['importlib.metadata']) is type(sys)  # the real module from now on
        assert got == md.entry_points(group='console_scripts') and len(got) > 0
    """)
    assert out.returncode == 0, out.stderr[-2000:]


def test_disabled_plugins_still_defer_importlib_metadata() -> None:
    """``PYDANTIC_DISABLE_PLUGINS`` set: robocfg leaves pydantic's cache alone (pydantic reads the
    variable itself) and the loader still comes without ``importlib.metadata``."""
    out = _python("""
        import os, sys
        os.environ['PYDANTIC_DISABLE_PLUGINS'] = '1'
        from robocfg.checks.task import load_task
        from robocfg.config import catalog
        load_task(catalog.find('tasks', 'pick_place'))
        from pydantic.plugin import _loader
        assert _loader._plugins is None and 'importlib.metadata' not in sys.modules
    """)
    assert out.returncode == 0, out.stderr[-2000:]


def test_a_name_other_than_entry_points_is_the_real_modules() -> None:
    """The stand-in for ``importlib.metadata`` inside the loader's import: ``entry_points`` and any
    other public name are the real module's (imported at that use), module attributes the import
    system probes are absent, and afterwards ``import importlib.metadata`` gives the real module."""
    out = _python("""
        import sys
        from robocfg.config.pydantic_plugins import METADATA, _DeferredMetadata
        stand_in = _DeferredMetadata(METADATA)
        assert not hasattr(stand_in, '__path__')
        assert 'importlib.metadata' not in sys.modules
        version = stand_in.version
        import importlib.metadata as md
        assert version is md.version and type(md) is type(sys)
        assert stand_in.entry_points(group='pydantic') == md.entry_points(group='pydantic')
    """)
    assert out.returncode == 0, out.stderr[-2000:]


def test_another_thread_importing_importlib_metadata_meanwhile_gets_the_real_module() -> None:
    """Another thread that imports ``importlib.metadata`` while pydantic's loader module executes
    (here: at the loader's first line, run from a trace function, one moment of that window) gets
    the real module by every spelling, never the stand-in: an import of a module found in
    ``sys.modules`` takes no lock (the loader's import holds only its own module's lock), so a
    stand-in there was what that thread got (and ``importlib.metadata.version`` an AttributeError,
    the import of a module already in ``sys.modules`` leaving its parent package's attribute unset).
    Afterwards the loader still runs without having imported the real module, and
    ``builtins.__import__`` is the interpreter's own."""
    out = _python("""
        import builtins, os, sys, threading
        LOADER_FILE = os.path.join('pydantic', 'plugin', '_loader.py')
        own_import = builtins.__import__
        got = {}
        def other():
            got['window'] = 'pydantic.plugin._loader' in sys.modules  # being executed
            import importlib.metadata as m
            got['as'] = type(m).__name__, getattr(m, '__file__', None) is not None
            import importlib.metadata
            got['dotted'] = importlib.metadata.version('pydantic')
            from importlib import metadata
            got['from'] = metadata is m
        def tracer(frame, event, arg):
            code = frame.f_code
            if event == 'call' and code.co_name == '<module>' and code.co_filename.endswith(LOADER_FILE) and not got:
                t = threading.Thread(target=other)
                t.start()
                t.join()
        sys.settrace(tracer)
        import robocfg.config.types
        sys.settrace(None)
        assert got['window'] is True and got['as'] == ('module', True), got
        assert got['from'] is True and got['dotted'], got
        from pydantic.plugin import _loader
        assert _loader._plugins == {} and builtins.__import__ is own_import
        assert type(sys.modules['importlib.metadata']) is type(sys)
    """)
    assert out.returncode == 0, out.stderr[-2000:]


def test_the_loader_of_pydantic_2_13_spelling_its_import_without_a_from_list_is_deferred_too(tmp_path: Path) -> None:
    """pydantic 2.13 (pyproject's lower bound) writes ``import importlib.metadata as
    importlib_metadata`` and calls ``importlib_metadata.distributions()`` in its scan; a loader
    module spelt so, executed as robocfg executes pydantic's, binds the stand-in (its
    ``distributions`` the real function, imported at that use), imports no ``importlib.metadata``,
    and a plain ``import importlib.metadata`` there gives an ``importlib`` whose other names are
    the real package's."""
    (tmp_path / "loader_2_13.py").write_text(textwrap.dedent("""
        from __future__ import annotations

        import importlib.metadata as importlib_metadata
        import importlib.metadata
        import os
        import warnings

        _plugins = None
        _loading_plugins = False
    """))
    out = _python(f"""
        import importlib.util, sys
        from robocfg.config.pydantic_plugins import _DeferredMetadata, _DeferringLoader
        spec = importlib.util.spec_from_file_location('loader_2_13', {str(tmp_path / 'loader_2_13.py')!r})
        spec.loader = _DeferringLoader(spec.loader)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        assert isinstance(module.importlib_metadata, _DeferredMetadata), module.importlib_metadata
        assert module.importlib.metadata is module.importlib_metadata
        assert 'importlib.metadata' not in sys.modules
        assert module._plugins == {{}}  # no distribution declares a plugin here: the cache filled
        assert module.importlib.import_module is importlib.import_module
        names = {{d.metadata['Name'] for d in module.importlib_metadata.distributions()}}
        import importlib.metadata as md
        assert names == {{d.metadata['Name'] for d in md.distributions()}} and 'pydantic' in names
        assert type(sys.modules['importlib.metadata']) is type(sys)
    """)
    assert out.returncode == 0, out.stderr[-2000:]
