"""Off-by-default flags read ``False``, not ``None``, so a command line that passes them by does
not load pydantic.

Typer coerces every parameter's value with a pydantic ``TypeAdapter`` it builds on first use,
except a bool flag whose value is already a bool. Its ``--help`` flag and the root's
``--install-completion`` / ``--show-completion`` default to ``None``, so every command line that
goes past them (``robocfg run pick-place --help`` goes past the root's and ``run``'s) imported
pydantic and built three or four adapters to hand ``None`` on (≈ 0.1 s of CPU). Their callbacks
treat ``False`` as ``None`` (nothing asked), so the flags behave as before.
"""

from __future__ import annotations

from typing import Any


def off_by_default(param: Any) -> Any:
    """``param`` (a typer bool flag, or None) with its default ``None`` made ``False``; in place."""
    if param is not None and getattr(param, "is_flag", False) and param.default is None:
        descriptor = getattr(param, "type_descriptor", None)
        if descriptor is not None and descriptor.annotation is bool:
            param.default = False
    return param
