"""Version of the ``--json`` run reports.

Every ``run`` command's report starts with ``"schema_version"``. Bumped whenever a field is
renamed, removed or changes meaning, so a reader of an older file can tell. Version 2:
``schema_version`` added to all five reports; pick-place and grasp gain ``interrupted`` and their
``object_start`` is the spawn position x, y, z in metres (it was x, y, yaw), the yaw moved to
``object_start_yaw_deg``.
The JSON Schema of each report: ``robocfg schema report-pick-place`` (and ``report-grasp``).
"""

REPORT_SCHEMA_VERSION = 2
