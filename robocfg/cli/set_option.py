"""``--set KEY=VALUE``: change one field of the task for this run, validated like the file.

Defined once here for every command that reads a task; the values go through
``robocfg.config.overrides`` (the same path as the Python API's ``with_overrides``), and a problem
in one is reported as ``--set pick_place.lift_height: message``.
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

SetOpt = Annotated[list[str] | None, typer.Option(
    "--set", metavar="KEY=VALUE",
    help="Change a task field for this run, e.g. --set pick_place.lift_height=0.2 or "
         "--set 'robots.0.position=[0.1, 0, 0]' (a YAML value; repeat for more fields).")]


def overrides(values: list[str] | None) -> dict[str, Any]:
    """The ``--set`` items as dotted key → value (empty when none were given)."""
    from robocfg.config.overrides import parse_assignments

    return parse_assignments(values or [])
