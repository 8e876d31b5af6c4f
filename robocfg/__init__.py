"""robocfg: robots and tasks from validated YAML, run headless in PyBullet."""

__version__ = "0.1.0"
