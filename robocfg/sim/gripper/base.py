"""Common interface of every gripper behaviour: what callers may rely on without probing.

Openings are fractions of the closed→open travel (0 closed, 1 open); widths are finger gaps in
metres; forces in N (or N·m for revolute drives). Commands are non-blocking: the World calls
``update()`` after every physics step.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, ClassVar

from robocfg.errors import RobocfgError

if TYPE_CHECKING:
    from robocfg.config.robot import GripperConfig
    from robocfg.sim.robot import ArmHandle, RobotHandle
    from robocfg.sim.world import World

OPEN, CLOSED = 1.0, -1.0


class Gripper(ABC):
    """A gripper on one arm. Subclasses implement every abstract method (the registry refuses a
    class that does not); the others have a meaning for every gripper and are overridden where
    the gripper can do more."""

    type_name: ClassVar[str] = ""
    grasps_at_surface: ClassVar[bool] = False  # True: holds an object by its surface (suction), not around it

    def __init__(self, world: World, arm: ArmHandle):
        self.world, self.arm = world, arm
        self.robot: RobotHandle = arm.robot
        if arm.config.gripper is None:
            raise RobocfgError(f"arm {arm.config.name!r} has no gripper")
        self.config: GripperConfig = arm.config.gripper
        self.client = self.robot.client

    def update(self) -> None:  # noqa: B027 (no-op by design: most grippers have nothing to advance)
        """Advance rate-limited targets, attach/detach... Called by the World after each step."""

    def busy(self) -> bool:
        """Whether ``update()`` may do something after the next physics step. While no gripper is
        busy (and no step hook is installed) the World steps without calling ``update()``
        (:mod:`robocfg.sim.playback`): only a command, never a physics step, makes a gripper busy.
        A subclass that overrides ``update`` is busy unless it overrides this too."""
        return type(self).update is not Gripper.update

    @abstractmethod
    def open(self) -> None:
        """Start opening (non-blocking)."""
        raise NotImplementedError

    @abstractmethod
    def close(self) -> None:
        """Start closing, or switch the grip on (non-blocking)."""
        raise NotImplementedError

    @abstractmethod
    def reset(self, fraction: float = 1.0) -> None:
        """Teleport to an opening ``fraction`` (1 open, 0 closed) and hold there, without dynamics
        (between episodes, or to measure the gripper at several openings)."""
        raise NotImplementedError

    def set_force(self, force: float) -> None:  # noqa: B027 (no-op by design for grippers without a force)
        """Cap the grip force (N, or N·m). Grippers without a force setting (suction) ignore it."""

    def refresh_contacts(self, body: int | str, touching_only: bool = False) -> bool:
        """Rebuild the finger links' contact points with ``body`` from the current geometry
        (:meth:`robocfg.sim.queries.SceneQueries.refresh_contacts`); ``touching_only``: only if a
        finger touches it. Returns whether they were rebuilt; a gripper without finger links
        (suction) has none to rebuild."""
        return False

    @abstractmethod
    def fraction(self) -> float:
        """Measured opening, 0 (closed) to 1 (open)."""
        raise NotImplementedError

    def fraction_at(self, q: list[float]) -> float:
        """The opening measured when the gripper's driven joints (``gripper_joints``, in order)
        stand at ``q``, for a gripper that measures it from them (a parallel one); the others
        measure it their own way (:meth:`fraction`)."""
        return self.fraction()

    def width(self) -> float | None:
        """Measured finger gap (m), or None for a gripper without fingers."""
        return None

    @abstractmethod
    def state(self) -> float:
        """1.0 (open) or −1.0 (closed)."""
        raise NotImplementedError

    @abstractmethod
    def is_grasping(self, body: int | str) -> bool:
        """True while ``body`` (a body id or a world body name) is held."""
        raise NotImplementedError

    def _body_id(self, body: int | str) -> int:
        return self.world.bodies[body] if isinstance(body, str) else int(body)
