"""Pure-data configuration: pydantic models and the YAML loader. Never imports simulators.

The modules that define models (``types``, ``cameras``, ``commands``, ``fixtures``,
``multi_pick``, ``robot``, ``scene``, ``task``) do without ``from __future__ import annotations``:
their field annotations are evaluated as the class is made, so pydantic takes the types as
objects instead of compiling and evaluating each annotation string (``typing.ForwardRef``) for
every model of every process. The models are the same (fields, validators, core and JSON
schemas). An annotation naming a class not defined yet (a validator returning its own class, a
name imported only for type checkers) is written as a string.
"""
