"""The config models' field annotations are objects, evaluated as each class is made (no postponed
annotations in the modules that define models: robocfg.config's docstring), so pydantic has no
annotation string to compile in any process."""

from __future__ import annotations

import importlib

import pytest
from pydantic import BaseModel

MODEL_MODULES = ("types", "cameras", "commands", "fixtures", "multi_pick", "robot", "scene", "task")


@pytest.mark.parametrize("name", MODEL_MODULES)
def test_model_modules_annotate_with_objects(name: str) -> None:
    module = importlib.import_module(f"robocfg.config.{name}")
    models = [v for v in vars(module).values()
              if isinstance(v, type) and issubclass(v, BaseModel) and v.__module__ == module.__name__]
    assert models
    for model in models:
        strings = {k: v for k, v in vars(model).get("__annotations__", {}).items() if isinstance(v, str)}
        assert not strings, f"{model.__name__}: annotations as strings {strings}"
