"""PyBullet simulation built from robot and task YAMLs: world, robot handle, mimic gears, grippers,
pictures. Modules here import pybullet at the top: the CLI imports them lazily."""
