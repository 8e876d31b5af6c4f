"""Silencing PyBullet's C-level prints (its build banner goes to fd 2, b3Warning lines to fd 1/2).

Pybullet-free on purpose: ``quiet_import()`` must run before ``import pybullet``.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator


@contextlib.contextmanager
def captured_stdout() -> Iterator[list[str]]:
    """Capture what C code writes to file descriptors 1 and 2; the lines land in the yielded list."""
    lines: list[str] = []
    streams = [s for s in (sys.stdout, sys.stderr) if _has_fd(s)]
    if not streams:
        yield lines
        return
    for s in streams:
        s.flush()
    fds = [s.fileno() for s in streams]
    saved = [os.dup(fd) for fd in fds]
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        for fd in fds:
            os.dup2(tmp.fileno(), fd)
        try:
            yield lines
        finally:
            _flush_c_stdio()
            for s in streams:
                with contextlib.suppress(Exception):
                    s.flush()
            for fd, sv in zip(fds, saved, strict=True):
                os.dup2(sv, fd)
                os.close(sv)
            tmp.seek(0)
            lines.extend(tmp.read().decode(errors="replace").splitlines())


def _has_fd(stream) -> bool:
    try:
        stream.fileno()
        return True
    except (AttributeError, OSError, ValueError):
        return False


def _flush_c_stdio() -> None:
    """Flush C's stdio buffers so text printed by C code lands in the capture, not later."""
    with contextlib.suppress(Exception):
        import ctypes

        ctypes.CDLL(None).fflush(None)


def quiet_import() -> None:
    """Import pybullet without its "pybullet build time" banner."""
    if "pybullet" in sys.modules:
        return
    with captured_stdout():
        import pybullet  # noqa: F401
