"""Assets: resolving URDF/mesh URIs and reading URDF structure (no simulator imports)."""
