"""Resolve the URIs a robot YAML may use for its URDF, and the mesh paths inside a URDF.

Supported URDF forms: a path relative to the YAML file (or absolute), ``pybullet_data://REL``,
``airo_models://NAME`` (a model name such as ``ur5e``) or ``airo_models://REL`` (a file inside
the package), and ``package://PKG/REL`` resolved through the YAML's ``package_dirs`` map.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass
from pathlib import Path


class UnresolvedPath(Exception):
    """A URI that does not point at an existing file; ``tried`` lists the candidates."""

    def __init__(self, uri: str, tried: list[Path], why: str = ""):
        self.uri, self.tried = uri, tried
        detail = why or ("tried: " + ", ".join(str(t) for t in tried) if tried else "")
        super().__init__(f"cannot resolve {uri!r}" + (f" ({detail})" if detail else ""))


def _package_root(module: str) -> Path | None:
    spec = importlib.util.find_spec(module)
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations)))


_MESH_HITS: dict[tuple, Path] = {}


@dataclass(frozen=True)
class Resolver:
    """Resolves URIs relative to ``base_dir`` (the YAML's folder) with a ``package_dirs`` map."""

    base_dir: Path
    package_dirs: dict[str, str] | None = None

    def urdf(self, uri: str) -> Path:
        """An existing URDF path for ``uri``, or UnresolvedPath."""
        if uri.startswith("pybullet_data://"):
            root = _package_root("pybullet_data")
            if root is None:
                raise UnresolvedPath(uri, [], "the pybullet package is not installed")
            return _exists(uri, [root / uri[len("pybullet_data://") :]])
        if uri.startswith("airo_models://"):
            rest = uri[len("airo_models://") :]
            root = _package_root("airo_models")
            if root is None:
                raise UnresolvedPath(uri, [], "the airo-models package is not installed")
            cands = [root / rest]
            if "/" not in rest:
                cands += sorted(root.glob(f"*/{rest}/{rest}.urdf")) + sorted(root.glob(f"*/{rest}/urdf/{rest}.urdf"))
            return _exists(uri, cands)
        if uri.startswith("package://"):
            return _exists(uri, self._package_candidates(uri, self.base_dir))
        p = Path(uri).expanduser()
        return _exists(uri, [p if p.is_absolute() else self.base_dir / p])

    def mesh(self, filename: str, urdf_path: Path) -> Path:
        """An existing mesh file referenced from ``urdf_path``, or UnresolvedPath listing what was tried.

        Hits are remembered per process (re-checked with one ``is_file``): a robot's meshes are
        looked up by several checks, and each miss-free lookup costs a few path resolutions."""
        key = (filename, urdf_path, self.base_dir, tuple(sorted((self.package_dirs or {}).items())))
        hit = _MESH_HITS.get(key)
        if hit is not None and hit.is_file():
            return hit
        found = self._mesh(filename, urdf_path)
        _MESH_HITS[key] = found
        return found

    def _mesh(self, filename: str, urdf_path: Path) -> Path:
        urdf_dir = urdf_path.parent
        if filename.startswith("file://"):
            filename = filename[len("file://") :]
        if filename.startswith("package://"):
            return _exists(filename, self._package_candidates(filename, urdf_dir))
        p = Path(filename)
        return _exists(filename, [p if p.is_absolute() else urdf_dir / p])

    def _package_candidates(self, uri: str, start: Path) -> list[Path]:
        rest = uri[len("package://") :]
        pkg, _, rel = rest.partition("/")
        cands: list[Path] = []
        if self.package_dirs and pkg in self.package_dirs:
            d = Path(self.package_dirs[pkg]).expanduser()
            cands.append((d if d.is_absolute() else self.base_dir / d) / rel)
        # PyBullet's behaviour: strip package:// and search relative to the URDF and its parents.
        for parent in [start, *list(start.parents)[:3]]:
            cands.append(parent / rest)
            cands.append(parent / rel)
        seen, out = set(), []
        for c in cands:
            if c not in seen:
                seen.add(c)
                out.append(c)
        return out


def _exists(uri: str, cands: list[Path]) -> Path:
    for c in cands:
        if c.is_file():
            return c.resolve()
    raise UnresolvedPath(uri, cands)


def body_asset(uri: str, base_dir: Path) -> Path:
    """The file of a task body's ``mesh`` (a mesh or a URDF): ``pybullet_data://REL``, absolute, or
    relative to the task file's folder ``base_dir``. UnresolvedPath when it does not exist."""
    if uri.startswith("pybullet_data://"):
        root = _package_root("pybullet_data")
        if root is None:
            raise UnresolvedPath(uri, [], "the pybullet package is not installed")
        return _exists(uri, [root / uri[len("pybullet_data://") :]])
    p = Path(uri).expanduser()
    return _exists(uri, [p if p.is_absolute() else base_dir / p])

