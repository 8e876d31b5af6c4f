"""How every command's ``--help`` reads: placeholders a person understands and whole summaries.

Typer names a value by its Python type (``<list[Path]>``, ``<float range>``,
``<float,float,float>...``) and cuts each command's summary at ~45 characters with "...". One
pass over the finished click command tree fixes both for every command, including the ones added
later, so no command module has to remember it:

* an option without an explicit ``metavar`` gets one from its type: ``PATH``, ``N`` (integer),
  ``X`` (number; its range, if any, is printed as ``x>=0.1`` beside it), ``X Y Z`` / ``X Y Z W``
  (a fixed number of numbers), ``a|b|c`` (choices), else its own name (``--arm ARM``);
* an argument is shown by its name in capitals (``TASK``, ``PATH...``) without the Python type;
* a command's summary in its group's listing is the first sentence of its help, never cut.
"""

from __future__ import annotations

import typing
from pathlib import Path

import typer.core
from typer._click import Command  # typer's own copy of click, whose commands typer builds


def polish(command: Command) -> None:
    """Apply the help conventions to ``command`` and every sub-command, in place."""
    if command.help and not command.short_help:
        command.short_help = first_sentence(command.help)
    for param in command.params:
        _placeholder(param)
    if isinstance(command, typer.core.TyperGroup):
        for sub in command.commands.values():
            polish(sub)


def first_sentence(text: str) -> str:
    """The first sentence of a help text's first paragraph, whole, on one line."""
    para = " ".join(text.strip().split("\n\n")[0].split())
    for i in range(1, len(para) - 1):
        if (para[i] == "." and para[i + 1] == " " and para[i - 1] != "."  # not an ellipsis
                and para[:i].count("`") % 2 == 0 and not para[:i].endswith(("e.g", "i.e", "etc"))):
            return para[: i + 1]
    return para


def _placeholder(param: object) -> None:
    if isinstance(param, typer.core.TyperArgument):
        if param.metavar is None:
            param.metavar = param.name.upper() if param.name else "VALUE"
        # The name says what to give; typer would append the Python type (``<str>``) after it.
        param.display_type_rich = lambda ctx: None  # type: ignore[method-assign]
        return
    if isinstance(param, typer.core.TyperOption) and param.metavar is None and not param.is_flag:
        param.metavar = _option_metavar(param)


def _option_metavar(param: typer.core.TyperOption) -> str:
    desc = param.type_descriptor
    annotation = desc.annotation
    if desc.is_choice and desc.choices:
        return "|".join(str(getattr(c, "value", c)) for c in desc.choices)
    if desc.is_tuple:
        n = len(typing.get_args(annotation))
        return " ".join("XYZW"[:n]) if n <= 4 else " ".join(f"X{i + 1}" for i in range(n))
    if desc.is_path or annotation is Path:
        return "PATH"
    if annotation is int:
        return "N"
    if annotation is float:
        return "X"
    long = max(param.opts, key=len).lstrip("-")
    return long.rsplit("-", 1)[-1].upper()
