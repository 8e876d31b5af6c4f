"""Version of the ``--json`` run reports.

Every ``run`` command's report starts with ``"schema_version"``. Bumped whenever a field is
renamed, removed or changes meaning, so a reader of an older file can tell. Version 2:
``schema_version`` added to all five reports; pick-place and grasp gain ``interrupted`` and their
``object_start`` is the spawn position x, y, z in metres (it was x, y, yaw), the yaw moved to
``object_start_yaw_deg``.
The JSON Schema of each report: ``robocfg schema report-pick-place`` (and ``report-grasp``).
"""

REPORT_SCHEMA_VERSION = 2


from dataclasses import dataclass, field  # noqa: E402


@dataclass
class FailedRunReport:
    """What ``--json`` holds when a run failed before it had a report of its own: a phase that
    needs no simulation (planning a trajectory through an unreachable waypoint, building the
    world) raised ``(phase, reason)``. ``success`` is false, as in every failed report, so a
    reader that checks ``success`` needs no special case; ``task`` is the task file's path."""

    kind: str  # the run kind: gripper, trajectory, follow-target, pick-place, grasp
    task: str
    robot: str
    phase: str
    reason: str
    success: bool = False
    schema_version: int = field(default=REPORT_SCHEMA_VERSION, kw_only=True)
