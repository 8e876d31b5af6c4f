"""Pure-data configuration: pydantic models and the YAML loader. Never imports simulators."""
