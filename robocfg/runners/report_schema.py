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


class SingleRunReport:
    """The report protocol's answers shared by the one-run kinds (gripper, trajectory,
    follow-target): a dataclass with ``success`` and ``interrupted`` whose one failure, if any,
    is told by its summary line."""

    success: bool
    interrupted: bool

    def to_dict(self) -> dict:
        from dataclasses import asdict

        return asdict(self)  # type: ignore[call-overload]

    def passed(self, min_success: float) -> bool:
        return self.success

    def failure_lines(self) -> list[str]:
        return []

    def episodes_finished(self) -> int:
        return 0 if self.interrupted else 1


def failed_episodes_line(labels: list[str], shown: int = 20) -> str:
    """``failed episodes: 3, 7 (cube), ...`` for a batch report's footer (first ``shown`` labels)."""
    more = " ..." if len(labels) > shown else ""
    return f"failed episodes: {', '.join(labels[:shown])}{more} (seeds and details in --json)"
