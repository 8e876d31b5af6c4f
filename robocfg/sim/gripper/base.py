"""Common interface of every gripper behaviour."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from robocfg.sim.robot import ArmHandle, RobotHandle

OPEN, CLOSED = 1.0, -1.0


class Gripper:
    """A gripper on one arm. Commands are non-blocking; the World calls ``update()`` every step."""

    type_name: ClassVar[str] = ""
    grasps_at_surface: ClassVar[bool] = False  # True: holds an object by its surface (suction), not around it

    def __init__(self, world: Any, arm: ArmHandle):
        self.world, self.arm = world, arm
        self.robot: RobotHandle = arm.robot
        self.config = arm.config.gripper
        self.client = self.robot.client

    def update(self) -> None:
        """Advance rate-limited targets, attach/detach... Called by the World after each step."""

    def open(self) -> None:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def state(self) -> float:
        """1.0 (open) or −1.0 (closed)."""
        raise NotImplementedError

    def is_grasping(self, body: int | str) -> bool:
        raise NotImplementedError

    def _body_id(self, body: int | str) -> int:
        return self.world.bodies[body] if isinstance(body, str) else int(body)
