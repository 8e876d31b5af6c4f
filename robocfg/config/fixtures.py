"""Static fixtures for task scenes: bins with walls, shelves with levels, plain blocks (tables).

A fixture is declared by its outer size and pose and expands into static boxes
(:meth:`Fixture.parts`), which the simulator spawns and the planner and the reactive controller
avoid like any obstacle. ``position`` is the centre of the fixture's *footprint* (the bottom face,
where it stands), ``euler_deg``/quaternion turn it about that point; ``size`` is [x, y, z] in the
fixture's own frame (m). Each part is a :class:`Body` named ``FIXTURE/PART`` (``bin_a/wall_+x``),
so contacts and failures name the part.
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import TYPE_CHECKING, Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from robocfg.config.types import Pose, PositiveFloat, Vec3, Vec4, new_list

if TYPE_CHECKING:
    from robocfg.config.scene import Body

GREY = [0.55, 0.55, 0.58, 1.0]


class _FixtureBase(Pose):
    name: str = Field(description="Unique name; its parts are called NAME/PART.")
    size: Vec3 = Field(description="Outer extents [x, y, z] (m) in the fixture's frame.")
    color: Vec4 = Field(default_factory=lambda: list(GREY), description="RGBA, 0..1.")
    friction: PositiveFloat = Field(1.0, description="Lateral friction coefficient of every part.")

    @model_validator(mode="after")
    def _positive_size(self):
        if any(s <= 0 for s in self.size):
            raise ValueError("'size' must be positive in every direction")
        return self

    def _box(self, part: str, size: list[float], centre: list[float]) -> "Body":
        """A part: ``centre`` in the fixture frame (origin at the footprint centre)."""
        from robocfg.config.scene import (
            Body,  # scene.py lists the fixtures: imported here, not at the top
        )
        from robocfg.geometry import matrix_to_pose, pose_matrix  # scipy: only when parts are built

        T_local = np.eye(4)
        T_local[:3, 3] = centre
        pos, quat = matrix_to_pose(pose_matrix(self) @ T_local)
        return Body(name=f"{self.name}/{part}", shape="box", size=[round(float(v), 9) for v in size],
                    position=[round(float(v), 9) for v in pos], quat_xyzw=[float(v) for v in quat], mass=0.0,
                    friction=self.friction, color=list(self.color))


class BinFixture(_FixtureBase):
    """An open-top bin: a floor and four walls of thickness ``wall``."""

    type: Literal["bin"] = Field(description="Selects the fixture kind.")
    wall: PositiveFloat = Field(0.01, description="Wall and floor thickness (m).")

    @model_validator(mode="after")
    def _room_inside(self):
        x, y, z = self.size
        if 2 * self.wall >= min(x, y) or self.wall >= z:
            raise ValueError(f"'wall' {self.wall:g} m leaves no room inside a {x:g} × {y:g} × {z:g} m bin")
        return self

    def parts(self) -> "list[Body]":
        x, y, z, w = *self.size, self.wall
        return [
            self._box("floor", [x, y, w], [0, 0, w / 2]),
            self._box("wall_+x", [w, y, z], [(x - w) / 2, 0, z / 2]),
            self._box("wall_-x", [w, y, z], [-(x - w) / 2, 0, z / 2]),
            self._box("wall_+y", [x - 2 * w, w, z], [0, (y - w) / 2, z / 2]),
            self._box("wall_-y", [x - 2 * w, w, z], [0, -(y - w) / 2, z / 2]),
        ]

    def floor_height(self) -> float:
        """Height (m) of the inside floor above the footprint."""
        return self.wall


class ShelfFixture(_FixtureBase):
    """An open shelf: two sides, a back panel on the +x side (open towards −x), a bottom board, a
    top board and a board at each of ``levels``."""

    type: Literal["shelf"] = Field(description="Selects the fixture kind.")
    board: PositiveFloat = Field(0.02, description="Board, side and back thickness (m).")
    levels: list[PositiveFloat] = Field(default_factory=new_list, description="Heights (m above the footprint) of the top faces of the intermediate boards.")

    @model_validator(mode="after")
    def _levels_inside(self):
        z = self.size[2]
        for h in self.levels:
            if not self.board < h < z - self.board:
                raise ValueError(f"shelf level {h:g} m is outside the shelf (between {self.board:g} and {z - self.board:g} m)")
        if sorted(self.levels) != list(self.levels):
            raise ValueError("'levels' must be given from the bottom up")
        return self

    def parts(self) -> "list[Body]":
        x, y, z, b = *self.size, self.board
        out = [
            self._box("back", [b, y, z], [(x - b) / 2, 0, z / 2]),
            self._box("side_+y", [x - b, b, z], [-b / 2, (y - b) / 2, z / 2]),
            self._box("side_-y", [x - b, b, z], [-b / 2, -(y - b) / 2, z / 2]),
            self._box("bottom", [x - b, y - 2 * b, b], [-b / 2, 0, b / 2]),
            self._box("top", [x - b, y - 2 * b, b], [-b / 2, 0, z - b / 2]),
        ]
        out += [self._box(f"level_{k + 1}", [x - b, y - 2 * b, b], [-b / 2, 0, h - b / 2])
                for k, h in enumerate(self.levels)]
        return out

    def level_heights(self) -> list[float]:
        """Top faces (m above the footprint) of the surfaces things can stand on: bottom, levels."""
        return [self.board, *self.levels]


class BlockFixture(_FixtureBase):
    """A solid block (a table top resting on the floor, a stand, a crate)."""

    type: Literal["block"] = Field(description="Selects the fixture kind.")

    def parts(self) -> "list[Body]":
        return [self._box("block", list(self.size), [0, 0, self.size[2] / 2])]


Fixture = Annotated[BinFixture | ShelfFixture | BlockFixture, Field(discriminator="type")]
