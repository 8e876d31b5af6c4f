"""Worlds that nothing draws go without PyBullet's TinyRenderer.

Every PyBullet client starts with the TinyRenderer plugin linked into PyBullet as its renderer,
and ``loadURDF``/``createMultiBody`` hand each new link to it: it reads the link's visual meshes,
or, for a robot loaded with ``URDF_IGNORE_VISUAL_SHAPES``, its *collision* meshes a second time,
and converts them for drawing. For the Panda that is ≈ 65 M instructions of a process's start
(callgrind; 5–10 ms of CPU), spent for pictures that a world built for physics never takes.

:func:`drop_renderer` unloads that plugin from one client (``pybullet.loadPlugin`` of the
built-in ``tinyRendererPlugin`` gives its id; ``unloadPlugin`` removes it): later bodies get no
visual shapes at all. The physics does not change (the renderer keeps its own copies of the
shapes; collision shapes, masses and inertias are built before it is called), which
``benchmarks/physics_hashes.py --compare`` checks step by step. Without it, ``getCameraImage``
returns a blank picture and ``getVisualShapeData`` fails or, in PyBullet 3.2.7's DIRECT client,
may never return (it loops on the previous command's status), so the functions that draw a client
or read its visual shapes call :func:`require_renderer` first and raise instead. A client has no way to
get the plugin back: a world that may be drawn must keep it (``World(visuals=True)``).
"""

from __future__ import annotations

import pybullet as p

from robocfg.errors import RobocfgError

BUILTIN = "tinyRendererPlugin"  # the name PyBullet registers its linked-in TinyRenderer under

_WITHOUT: set[int] = set()  # clients whose renderer was dropped (ids are reused after a disconnect)


def drop_renderer(client: int) -> bool:
    """Unload the built-in TinyRenderer from ``client`` (before any body is loaded); True when it
    was there and is gone. A PyBullet built without it (``loadPlugin`` fails) is left as it is."""
    from robocfg.sim.quiet import captured_stdout

    with captured_stdout():  # a failed loadPlugin prints b3Warning lines
        uid = p.loadPlugin(BUILTIN, physicsClientId=client)
    if uid < 0:
        return False
    p.unloadPlugin(uid, physicsClientId=client)
    _WITHOUT.add(client)
    return True


def forget(client: int) -> None:
    """``client`` is disconnected (its id may be given to a new client, which has a renderer)."""
    _WITHOUT.discard(client)


def has_renderer(client: int) -> bool:
    """Whether ``client`` can draw (its renderer was not dropped)."""
    return client not in _WITHOUT


def require_renderer(client: int) -> None:
    """Raise ``RobocfgError`` if ``client``'s renderer was dropped: it would draw blank pictures."""
    if client in _WITHOUT:
        raise RobocfgError(f"PyBullet client {client} was built without a renderer (nothing was to draw "
                           "its world: World(visuals=False)); build the world with visuals=True to take pictures")
