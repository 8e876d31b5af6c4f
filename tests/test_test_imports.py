"""The suite must import the way CI runs it: from a clean clone, with only ``tests/`` on
``sys.path`` (pytest's rootdir insertion), never the repository root.

A development shell often has the repository root on ``PYTHONPATH``, which hides an
``import tests.x`` that then fails on CI with ``ModuleNotFoundError: No module named 'tests'``.
This test reads the test modules' import statements instead of trusting the shell.
"""

from __future__ import annotations

import ast
from pathlib import Path

TESTS = Path(__file__).resolve().parent


def _imports_of_tests_package(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "tests" or node.module.startswith("tests."):
                found.append(f"{path.name}:{node.lineno}: from {node.module} import ...")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == "tests" or alias.name.startswith("tests."):
                    found.append(f"{path.name}:{node.lineno}: import {alias.name}")
    return found


def test_no_test_module_imports_the_tests_package() -> None:
    offenders = [hit for p in sorted(TESTS.glob("*.py")) for hit in _imports_of_tests_package(p)]
    assert not offenders, "import helpers as `from _cli import ...`:\n" + "\n".join(offenders)
