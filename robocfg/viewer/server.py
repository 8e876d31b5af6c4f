"""``robocfg view`` without ``--png``: serve the browser viewer and reload when a YAML is saved.

The YAML files shown (the robot or task YAML and every robot YAML a task names) are polled for
changes every ``poll_s`` seconds; a change rebuilds the page (or shows the new errors in it).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

from robocfg.viewer.browser import BrowserViewer
from robocfg.viewer.playback import Playback
from robocfg.viewer.source import ViewSource


def _stamps(paths: Sequence[Path]) -> tuple[tuple[str, int | None, int | None], ...]:
    """(path, modification time in ns, size in bytes) of each file; None, None where it is missing."""
    out: list[tuple[str, int | None, int | None]] = []
    for p in paths:
        try:
            st = Path(p).stat()
            out.append((str(p), st.st_mtime_ns, st.st_size))
        except OSError:
            out.append((str(p), None, None))
    return tuple(out)


def watch(viewer: BrowserViewer, poll_s: float = 0.5, until: Callable[[], bool] = lambda: False) -> None:
    """Reload ``viewer`` whenever one of its YAML files changes, until ``until()`` is true."""
    seen = _stamps(viewer.watched)
    while not until():
        time.sleep(poll_s)
        now = _stamps(viewer.watched)
        if now != seen:
            viewer.reload()
            seen = _stamps(viewer.watched)


def serve(source: ViewSource, host: str = "127.0.0.1", port: int = 8080, q: Sequence[float] | None = None,
          on_ready: Callable[[str], None] = lambda url: None, playback: Playback | None = None) -> None:
    """Run the viewer until Ctrl-C (with ``playback``: a recorded run to play in the page)."""
    viewer = BrowserViewer(source, host=host, port=port, q=q, playback=playback)
    on_ready(viewer.url)
    try:
        watch(viewer)
    except KeyboardInterrupt:
        pass
    finally:
        viewer.stop()
