"""Reads of one physics state, made once: a memo of PyBullet reads kept while the world's state
cannot have changed.

A pick-place episode asks a few things twice without a physics step in between (the arm's joints
at the grasp choice and again at the move it chooses; the finger gap at the end of the grasp and
again for the grip's acceleration budget; the object's pose at the lift check and again to carry
it; the EE pose at the last convergence poll and again to carry the object; the object's pose at
the placed check and again for the record). Each such read is a PyBullet state query (≈ 10 µs in
situ: the client copies its fixed-size state buffer per query). :class:`SameStepReads` gives the
second asker the first one's value.

Freshness: a value is kept only while :attr:`World.read_stamp <robocfg.sim.world.World.read_stamp>`
— (physics steps, teleports) — is what it was when the value was read. Every physics step moves
``World.steps`` (``World.step`` and every playback loop count their steps before any callback
runs), and every change of state without a step moves ``World.teleports``: ``set_body_pose``,
``add_body``, ``remove_body``, ``restore`` and any robot's ``reset_joints`` (its gripper's and
mimic gears' resets go through it). Motor commands change nothing until the next step. Only what
changes the state through PyBullet directly, not through the world or a robot handle, is not seen:
robocfg's own code does not (only ``robocfg.sim`` imports pybullet, and it teleports through those
methods); code that does must not read through a ``SameStepReads``.

Values are stored as read and handed out as they are: store immutable values (tuples, floats) or
copy mutable ones when handing them out.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING, TypeVar

if TYPE_CHECKING:
    from robocfg.sim.world import World

T = TypeVar("T")


class SameStepReads:
    """Values read from ``world`` at its current state, by key (see the module docstring)."""

    def __init__(self, world: World):
        self.world = world
        self._stamp: tuple[int, int] | None = None
        self._values: dict[Hashable, object] = {}

    def get(self, key: Hashable, read: Callable[[], T]) -> T:
        """The value of ``key`` read at the world's current state: ``read()``'s, called only when
        nothing was read under ``key`` since the state last changed."""
        w = self.world
        stamp = (w.steps, w.teleports)  # World.read_stamp, inlined
        if stamp != self._stamp:
            self._values.clear()
            self._stamp = stamp
        elif key in self._values:
            return self._values[key]  # type: ignore[return-value]  # stored by this very key's read
        value = self._values[key] = read()
        return value

    def put(self, key: Hashable, value: object) -> None:
        """Note ``value`` as just read under ``key`` at the world's current state (a read made by
        other means, e.g. a polling loop's last)."""
        w = self.world
        stamp = (w.steps, w.teleports)
        if stamp != self._stamp:
            self._values.clear()
            self._stamp = stamp
        self._values[key] = value
