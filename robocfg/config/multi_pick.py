"""Parameter block of ``run pick-place-many`` and its task model: several objects, each with its own
randomisation region, picked in turn (out of clutter or a bin) and placed into a bin or onto a
shelf level. Made when a task of this kind is first validated (``robocfg.config.task.TASK_MODELS``),
not in every process.

Units: m, deg where the key says so, s. Positions are world coordinates.
"""

# Annotations are evaluated as each class is made (no postponed annotations: robocfg.config's docstring).

from typing import Annotated, Literal

from pydantic import Field, model_validator

from robocfg.config.commands import PhaseTimeouts, Region
from robocfg.config.scene import Body
from robocfg.config.task_base import TaskBase
from robocfg.config.types import FiniteFloat, Frozen, NonNegFloat, PositiveFloat


class PickObject(Body):
    """One object of the scene to pick: a body (spawned resting on what is below it) and the region
    its position and yaw are randomised in, episode by episode."""

    region: Region = Field(default_factory=Region, description="± x/y range (m) and ± yaw range (deg) of this object's spawn pose.")


class PlaceInto(Frozen):
    """Where the objects go: a bin (``scene.fixtures`` entry of type bin) or a shelf level. The
    place spots are a grid inside the bin's walls (or along the shelf board), spaced so that placed
    objects keep ``gap`` from each other and from the walls; the objects take them in order."""

    fixture: str = Field(description="Name of the bin or shelf in scene.fixtures.")
    level: Annotated[int, Field(ge=0)] = Field(0, description="Shelf only: 0 = the bottom board, k = the board at levels[k-1].")
    gap: PositiveFloat = Field(0.03, description="Clearance (m) between placed objects, and between them and the walls.")
    depth: Annotated[float, Field(gt=0, lt=1)] = Field(0.5, description="Shelf only: how far in the spots are, as a fraction of the board's depth from the open front.")


class PickPlaceManyParams(Frozen):
    """``run pick-place-many``: pick each object in turn and place it into a bin or onto a shelf
    level, the free-space moves planned collision-free (or IK + min-jerk trajectories)."""

    objects: Annotated[list[PickObject], Field(min_length=1)] = Field(description="The objects to pick (names unique in the scene).")
    place: PlaceInto = Field(description="The bin or shelf level the objects go to.")
    order: Literal["listed", "reachability"] = Field("listed", description="listed: in the order given; reachability: at each turn the object whose collision-free grasp needs the least joint travel (objects without one wait for their neighbours to be cleared).")
    above_height: PositiveFloat = Field(0.12, description="TCP height above the grasp point for pre-grasp (m).")
    lift_height: PositiveFloat = Field(0.12, description="How far the object is lifted (m); also the height above a bin spot it is carried to before lowering.")
    place_clearance: PositiveFloat = Field(0.03, description="Shelf: how far above its resting height (m) the object is carried in before it is lowered (it must fit under the board above).")
    grasp_depth: FiniteFloat | None = Field(None, description="TCP height of the grasp relative to the object centre (m); leave it out to choose it from the geometry.")
    clutter_margin: NonNegFloat = Field(0.003, description="Clearance (m) the whole gripper and arm must keep from neighbouring objects and fixtures at the grasp and pre-grasp configurations (candidate grasps that do not are dropped).")
    position_tolerance: PositiveFloat = Field(0.005, description="Phase convergence: TCP position error (m).")
    orientation_tolerance: PositiveFloat = Field(0.05, description="Phase convergence: TCP orientation error (rad).")
    timeouts: PhaseTimeouts = Field(default_factory=PhaseTimeouts, description="Per-phase time limits (s), each object's phases alike (a shelf's withdraw phase: its planned duration × 1.25 + 1 s).")
    motion: Literal["trajectory", "planned"] = Field("planned", description="Free-space moves (pre-grasp, transport, withdraw): 'planned' = collision-free joint paths (OMPL RRT-Connect, 1 cm clear of the scene, the other objects and the held object included); 'trajectory' = IK + min-jerk.")
    speed_scale: Annotated[float, Field(gt=0, le=1)] = Field(0.5, description="Fraction of joint velocity limits used.")
    grip_force: PositiveFloat | None = Field(None, description="Overrides the gripper's max_force.")
    success_tolerance: PositiveFloat = Field(0.02, description="Horizontal place error allowed per object (m).")
    max_tilt_deg: PositiveFloat = Field(15.0, description="Largest tilt (deg) of a placed object from how it lay.")

    @model_validator(mode="after")
    def _objects(self) -> "PickPlaceManyParams":
        names = [o.name for o in self.objects]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"object names must be unique: {dup}")
        if any(o.mass <= 0 for o in self.objects):
            raise ValueError("every object's mass must be > 0 (a static object cannot be picked)")
        return self


class PickPlaceManyTask(TaskBase):
    task: Literal["pick_place_many"] = Field(description="The command this file configures; selects the parameter block.")
    pick_place_many: PickPlaceManyParams = Field(description="Parameters of `robocfg run pick-place-many`.")
