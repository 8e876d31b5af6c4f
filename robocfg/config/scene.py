"""Scene models for task YAMLs: ground, table, pedestal, objects, obstacles. Sizes in metres, mass in kg."""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.fixtures import Fixture
from robocfg.config.types import Frozen, NonNegFloat, Pose, PositiveFloat, Vec3, Vec4, new_list

Color = Vec4


class Body(Pose):
    """A primitive body. ``size`` means: box → full extents [x, y, z]; sphere → [radius];
    cylinder/capsule → [radius, length]; mesh → scale [sx, sy, sz]."""

    name: str = Field(description="Unique name, used by commands and reports.")
    shape: Literal["box", "sphere", "cylinder", "capsule", "mesh"] = Field("box", description="Decides what size means (see above).")
    size: Annotated[list[PositiveFloat], Field(min_length=1, max_length=3)] = Field(description="See class doc (m).")
    mesh: str | None = Field(None, description="Mesh or URDF path for shape: mesh (relative, or pybullet_data://).")
    mass: NonNegFloat = Field(0.1, description="kg; 0 makes the body static.")
    friction: PositiveFloat = Field(1.0, description="Lateral friction coefficient.")
    color: Color = Field(default_factory=lambda: [0.8, 0.3, 0.2, 1.0], description="RGBA, 0..1.")

    @model_validator(mode="after")
    def _size_for_shape(self) -> "Body":
        need = {"box": 3, "sphere": 1, "cylinder": 2, "capsule": 2, "mesh": 3}[self.shape]
        if len(self.size) != need:
            raise ValueError(f"'size' needs {need} value(s) for shape '{self.shape}', got {len(self.size)}")
        if self.shape == "mesh" and not self.mesh:
            raise ValueError("shape 'mesh' needs a 'mesh' path")
        return self

    def half_height(self) -> float:
        """Half the extent along the body's own z axis (m)."""
        if self.shape in ("box", "mesh"):
            return self.size[2] / 2
        if self.shape == "sphere":
            return self.size[0]
        return self.size[1] / 2 + (self.size[0] if self.shape == "capsule" else 0.0)


class Table(Pose):
    """A static box table; ``position`` is the centre of its top surface."""

    size: Vec3 = Field(default_factory=lambda: [0.8, 1.2, 0.05], description="Top extents (m).")
    color: Color = Field(default_factory=lambda: [0.6, 0.5, 0.4, 1.0], description="RGBA, 0..1.")
    friction: PositiveFloat = Field(1.0, description="Lateral friction coefficient.")


class Pedestal(Pose):
    """A static cylinder the robot stands on; ``position`` is the centre of its top face."""

    radius: PositiveFloat = Field(0.15, description="m.")
    height: PositiveFloat = Field(0.5, description="m; the top face is at position.")
    color: Color = Field(default_factory=lambda: [0.3, 0.3, 0.3, 1.0], description="RGBA, 0..1.")


class Scene(Frozen):
    """Everything in the world except the robots."""

    ground: bool = Field(True, description="Add a ground plane at z = 0.")
    table: Table | None = Field(None, description="Optional static table.")
    pedestal: Pedestal | None = Field(None, description="Optional static pedestal (place the robot on its top face).")
    objects: list[Body] = Field(default_factory=new_list, description="Movable objects (names unique among objects and obstacles).")
    obstacles: list[Body] = Field(default_factory=new_list, description="Static obstacles (mass is ignored).")
    fixtures: list[Fixture] = Field(default_factory=new_list, description="Static fixtures built from boxes: bins (type: bin), shelves with levels (type: shelf), blocks (type: block); parts are named FIXTURE/PART.")

    def fixture_parts(self) -> list[Body]:
        """Every fixture's boxes (static bodies, world poses)."""
        return [part for f in self.fixtures for part in f.parts()]


class Sim(Frozen):
    """Simulation settings."""

    timestep: PositiveFloat = Field(1.0 / 240.0, description="Physics step (s).")
    seed: int = Field(0, ge=0, description="Seed for every random choice (>= 0).")
    gui: bool = Field(False, description="Open the PyBullet GUI (same as --gui).")
    max_duration: PositiveFloat = Field(60.0, description="Simulated-time cap for a run (s).")
    gravity: Vec3 = Field(default_factory=lambda: [0.0, 0.0, -9.81], description="m/s².")
    solver_iterations: int | None = Field(None, ge=1, description="Overrides the robot's physics.solver_iterations.")
