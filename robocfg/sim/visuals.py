"""Per-material colours for multi-material OBJ visuals.

PyBullet colours a whole OBJ visual with one material (the first) unless
``URDF_USE_MATERIAL_COLORS_FROM_MTL`` is set, and that flag also overrides colours the URDF gives
and mis-colours some textured meshes. So instead, an untextured OBJ that uses several materials
and has no ``<material>`` in its URDF ``<visual>`` is split into one OBJ per material (cached in the
temp folder) and the visual becomes one ``<visual>`` per part with the material's ``Kd`` colour.
(airo-models' UR5e renders all black without this.)
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

DEFAULT_RGBA = (0.7, 0.7, 0.7, 1.0)


def _materials(obj: Path, mtllibs: list[str]) -> tuple[dict[str, tuple[float, float, float, float]], bool]:
    """Kd colours (with ``d`` alpha) by material name, and whether any material has a texture."""
    colors: dict[str, list[float]] = {}
    textured, cur = False, None
    for lib in mtllibs:
        path = obj.parent / lib
        if not path.is_file():
            continue
        for line in path.read_text(errors="replace").splitlines():
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "newmtl" and len(parts) > 1:
                cur = parts[1]
                colors[cur] = list(DEFAULT_RGBA)
            elif cur is not None and parts[0] == "Kd" and len(parts) >= 4:
                colors[cur][:3] = [float(v) for v in parts[1:4]]
            elif cur is not None and parts[0] == "d" and len(parts) >= 2:
                colors[cur][3] = float(parts[1])
            elif parts[0].startswith("map_"):
                textured = True
    return {k: tuple(v) for k, v in colors.items()}, textured  # type: ignore[misc]


def split_by_material(obj: Path) -> list[tuple[Path, tuple[float, float, float, float]]] | None:
    """One OBJ per material used by ``obj`` with its colour, or None when there is nothing to split
    (fewer than two materials, a texture, or no material library)."""
    text = obj.read_text(errors="replace")
    if text.count("usemtl") < 2:
        return None
    lines = text.splitlines()
    mtllibs = [ln.split(maxsplit=1)[1].strip() for ln in lines if ln.startswith("mtllib ") and len(ln.split()) > 1]
    colors, textured = _materials(obj, mtllibs)
    if textured or not colors:
        return None
    key = hashlib.sha1(f"{obj.resolve()}:{obj.stat().st_mtime_ns}".encode()).hexdigest()[:12]
    out_dir = Path(tempfile.gettempdir()) / "robocfg_obj" / f"{obj.stem}_{key}"
    verts: dict[str, list[str]] = {"v": [], "vt": [], "vn": []}
    faces: dict[str, list[list[str]]] = {}
    cur = "__none__"
    for ln in lines:
        tag, _, rest = ln.partition(" ")
        if tag in verts:
            verts[tag].append(rest.strip())
        elif tag == "usemtl":
            cur = rest.strip()
        elif tag == "f":
            faces.setdefault(cur, []).append([_absolute(t, verts) for t in rest.split()])
    used = [m for m, f in faces.items() if f]
    if len(used) < 2:
        return None
    parts = []
    for k, mat in enumerate(used):
        path = out_dir / f"part{k}.obj"
        if not path.is_file():
            _write_part(path, verts, faces[mat])
        parts.append((path, colors.get(mat, DEFAULT_RGBA)))
    return parts


def _absolute(token: str, verts: dict[str, list[str]]) -> str:
    """A face corner ``v/vt/vn`` with negative (relative) indices made absolute."""
    fields = token.split("/")
    for i, kind in enumerate(("v", "vt", "vn")):
        if i < len(fields) and fields[i] and int(fields[i]) < 0:
            fields[i] = str(len(verts[kind]) + 1 + int(fields[i]))
    return "/".join(fields)


def _write_part(path: Path, verts: dict[str, list[str]], faces: list[list[str]]) -> None:
    remap: dict[str, dict[int, int]] = {"v": {}, "vt": {}, "vn": {}}
    out_faces = []
    for face in faces:
        corners = []
        for token in face:
            fields = token.split("/")
            for i, kind in enumerate(("v", "vt", "vn")):
                if i < len(fields) and fields[i]:
                    old = int(fields[i])
                    fields[i] = str(remap[kind].setdefault(old, len(remap[kind]) + 1))
            corners.append("/".join(fields))
        out_faces.append("f " + " ".join(corners))
    body = []
    for kind in ("v", "vt", "vn"):
        src = verts[kind]
        body += [f"{kind} {src[old - 1]}" for old in remap[kind]]  # dicts keep insertion order = new index order
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp")
    tmp.write_text("\n".join([*body, *out_faces]) + "\n")
    tmp.replace(path)
