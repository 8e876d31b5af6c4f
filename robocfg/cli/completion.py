"""Shell completion of robot and task names (``robocfg --install-completion`` turns it on).

Names come from the search path, as the commands find them: ``./robots`` (``./tasks``),
``$ROBOCFG_PATH``, then the built-ins. A ``run KIND`` command completes only the tasks of its
kind; a task's kind is read from its ``task:`` line without validating the file.
"""

from __future__ import annotations

from collections.abc import Callable


def robot_names(incomplete: str) -> list[str]:
    """Robot names starting with ``incomplete``."""
    from robocfg.config import catalog

    return [n for n in catalog.available("robots") if n.startswith(incomplete)]


def task_names(kind: str | None = None) -> Callable[[str], list[str]]:
    """A completer of task names starting with what was typed; only ``task: KIND`` files when
    ``kind`` is given."""

    def complete(incomplete: str) -> list[str]:
        from robocfg.config import catalog
        from robocfg.config.load import load_yaml
        from robocfg.errors import ConfigError

        out = []
        for name, path in catalog.available("tasks").items():
            if not name.startswith(incomplete):
                continue
            try:
                if kind is None or load_yaml(path).data.get("task") == kind:
                    out.append(name)
            except ConfigError:  # an unreadable file is no candidate
                continue
        return out

    return complete
