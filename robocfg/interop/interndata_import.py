"""``robocfg import interndata``: an InternDataEngine robot YAML (+ the URDF its USD came from) →
a robocfg robot YAML, fully validated, every problem reported at its line in *their* file.

Steps: read their file (line marks kept), set aside its ``robocfg:`` block (written by our
exporter), report keys outside their template as dropped, validate the rest
(:class:`InterndataRobot`), map it onto our fields against the URDF (:func:`map_interndata`),
lay the block over the result, fill what their format cannot say (the gripper's closed position
and finger links) from the URDF the way ``robocfg new-robot`` does, then run robocfg's complete
robot checks on the written file and translate their findings back to their file's lines.
"""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from robocfg.assets.compose import CompositionError, Part, compose
from robocfg.assets.draft import _uri
from robocfg.assets.draft_gripper import UnsupportedGripper, parallel_gripper
from robocfg.assets.paths import Resolver, UnresolvedPath
from robocfg.assets.urdf import Urdf, UrdfParseError, missing_link_mass
from robocfg.assets.urdf_xml import parse_urdf
from robocfg.checks import CheckedRobot, load_robot
from robocfg.config.load import Loc, YamlDocument, format_loc, load_yaml
from robocfg.config.robot import Attachment
from robocfg.config.validation import _MISSING, _lookup, validate_document
from robocfg.errors import ConfigError, Problem
from robocfg.interop.extension import BLOCK_KEY, overlay, rebase_paths
from robocfg.interop.interndata_map import Dropped, Mapped, map_interndata
from robocfg.interop.interndata_schema import InterndataRobot
from robocfg.suggest import did_you_mean


@dataclass
class ImportResult:
    """What ``import interndata`` wrote and what the user should read."""

    output: Path
    robot: CheckedRobot
    dropped: list[Dropped] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # values derived rather than read
    warnings: list[Problem] = field(default_factory=list)  # on their file where the field came from it


def import_interndata(their_path: Path, output: Path, urdf: str | None = None) -> ImportResult:
    """Convert ``their_path`` and write ``output`` (replacing it). ``urdf``: a path or URI of the
    robot's URDF; may be left out when their file carries a ``robocfg:`` block with one.
    Raises ConfigError (their file's lines) without writing anything when the result is invalid."""
    doc = load_yaml(their_path)
    data = dict(doc.data)
    block = data.pop(BLOCK_KEY, None)
    if block is not None and not isinstance(block, dict):
        raise ConfigError([doc.problem((BLOCK_KEY,), "must be a mapping (robocfg fields with no InternDataEngine key)")])
    dropped: list[Dropped] = []
    known = list(InterndataRobot.model_fields)
    for key in list(data):
        if key not in known and not did_you_mean(str(key), known):
            data.pop(key)
            dropped.append(Dropped(str(key), "not a key of InternDataEngine's robot template"))
    their: InterndataRobot = validate_document(YamlDocument(doc.path, data, doc.marks), InterndataRobot)
    out_dir = output.parent
    out_dir.mkdir(parents=True, exist_ok=True)  # relative paths are resolved from it ("dir/../x" needs dir)
    block = rebase_paths(block or {}, doc.path.parent, out_dir)
    robot: dict[str, Any] = {"schema_version": 1, "name": re.sub(r"[^A-Za-z0-9_\-]", "_", output.stem),
                             "description": f"Imported from the InternDataEngine config {their_path.name}."}
    if urdf is not None:
        for key in ("urdf", "attachments", "package_dirs"):
            if block.pop(key, None) is not None:
                dropped.append(Dropped(f"{BLOCK_KEY}.{key}", "--urdf given: that URDF is the whole robot"))
        robot["urdf"] = urdf if "://" in urdf else _uri(Path(urdf), out_dir)
        parsed = _parse(doc, robot["urdf"], [], {}, out_dir)
    elif isinstance(block.get("urdf"), str):
        parsed = _parse(doc, block["urdf"], block.get("attachments") or [], block.get("package_dirs") or {}, out_dir)
    else:
        raise ConfigError([Problem(str(doc.path), None, None, "", "pass --urdf ROBOT.urdf: their file names a USD "
                                   f"(path: {their.path!r}), which robocfg cannot load; give the URDF it was made from")])
    mapped = map_interndata(doc, their, parsed)
    if "arms" in block and (not isinstance(block["arms"], list) or len(block["arms"]) != len(mapped.robot["arms"])):
        raise ConfigError([doc.problem((BLOCK_KEY, "arms"), f"needs one entry per arm ({len(mapped.robot['arms'])}: "
                                       f"{', '.join(their.sides)}), in the order left, right")])
    robot = overlay({**robot, **mapped.robot}, block)
    notes = list(mapped.notes)
    _fill_grippers(robot, mapped, parsed, notes)
    _fill_masses(robot, parsed, notes)
    checked, warnings = _validate(doc, robot, mapped, block, output)
    return ImportResult(output, checked, dropped + mapped.dropped, notes, mapped.warnings + warnings)


def _parse(doc: YamlDocument, uri: str, attachments: list[Any], package_dirs: dict[str, str], out_dir: Path) -> Urdf:
    """The robot's URDF (composed with the block's attachments), resolved from ``out_dir``."""
    resolver = Resolver(out_dir, package_dirs)
    try:
        path = resolver.urdf(uri)
        if attachments:
            parts = []
            for i, a in enumerate(attachments):
                try:
                    att = Attachment.model_validate(a)
                except ValueError as exc:
                    raise ConfigError([doc.problem((BLOCK_KEY, "attachments", i), f"not an attachment: {exc}")]) from None
                parts.append(Part.of(att, resolver.urdf(att.urdf)))
            path = compose(path, parts, resolver).path
        return parse_urdf(path)
    except UnresolvedPath as exc:
        raise ConfigError([doc.problem((BLOCK_KEY,) if attachments or uri else (), f"URDF not found: {exc}")]) from None
    except CompositionError as exc:
        raise ConfigError([doc.problem((BLOCK_KEY, "attachments"), pr.message) for pr in exc.problems]) from None
    except UrdfParseError as exc:
        raise ConfigError([Problem(uri, exc.line, None, "", f"URDF does not parse: {exc}")]) from None


def _fill_grippers(robot: dict[str, Any], mapped: Mapped, urdf: Urdf, notes: list[str]) -> None:
    """A parallel gripper's fields their format lacks (closed position, finger links, widths), from
    the URDF's joint limits and finger geometry as ``robocfg new-robot`` finds them."""
    for i, arm in enumerate(robot["arms"]):
        g = arm.get("gripper")
        if not isinstance(g, dict) or g.get("type", "parallel") != "parallel":
            continue
        need = [k for k in ("open", "closed", "finger_links", "max_width") if k not in g]
        if not need or arm.get("ee_link") not in urdf.links:
            continue
        try:
            found = parallel_gripper(urdf, Resolver(urdf.path.parent), arm["ee_link"], mapped.leaders.get(i) or list(g["joints"]))
        except UnsupportedGripper:
            found = None
        if found is None or found.gripper is None:
            notes.append(f"arms[{i}].gripper: the finger links could not be found from the URDF geometry; add them "
                         f"under '{BLOCK_KEY}: arms: [{{gripper: {{finger_links: [A, B]}}}}]' in the input")
            continue
        draft = found.gripper
        if "open" in g and "closed" in need:
            # The closed position is the joint limit farther from the open one.
            g["closed"] = [_far_limit(urdf, j, q) for j, q in zip(draft.joints, g["open"], strict=True)]
        for key in need:
            g.setdefault(key, getattr(draft, key))
        if "max_width" in need:
            g.setdefault("min_width", draft.min_width)
        notes.append(f"arms[{i}].gripper: {', '.join(need)} derived from the URDF (joint limits, finger geometry) "
                     f"— finger_links {g['finger_links']}, closed {g['closed']}")


def _fill_masses(robot: dict[str, Any], urdf: Urdf, notes: list[str]) -> None:
    """Small masses for the links without ``<inertial>`` (PyBullet would load each as 1 kg), as
    ``robocfg new-robot`` writes them; masses the input gives are kept."""
    physics = robot.setdefault("physics", {})
    given = physics.get("link_masses") or {}
    extra = {j.child: missing_link_mass(urdf.links[j.child]) for j in urdf.joints.values()
             if j.child in urdf.links and urdf.links[j.child].mass is None and j.child not in given}
    if extra:
        physics["link_masses"] = {**given, **extra}
        notes.append(f"physics.link_masses: links without <inertial> get 0.01 kg (with geometry) or 0.001 kg: {sorted(extra)}")


def _far_limit(urdf: Urdf, joint: str, q: float) -> float:
    j = urdf.joints[joint]
    return j.lower if abs(q - j.lower) > abs(q - j.upper) else j.upper


def _validate(doc: YamlDocument, robot: dict[str, Any], mapped: Mapped, block: dict[str, Any],
              output: Path) -> tuple[CheckedRobot, list[Problem]]:
    """Write ``robot`` next to ``output``, run the robot checks, move it into place if valid."""
    text = f"# Imported from {doc.path.name} by `robocfg import interndata`.\n" + yaml.safe_dump(
        robot, sort_keys=False, default_flow_style=None, width=120, allow_unicode=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{output.stem}.", suffix=".yaml", dir=output.parent)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
    try:
        checked = load_robot(tmp)
    except ConfigError as exc:
        os.unlink(tmp)
        raise ConfigError([_to_theirs(p, doc, mapped, block) for p in exc.problems]) from None
    except BaseException:
        os.unlink(tmp)
        raise
    os.replace(tmp, output)
    checked = load_robot(output)
    return checked, [_to_theirs(p, doc, mapped, block) for p in checked.warnings]


def _parse_loc(path: str) -> Loc:
    return tuple(int(i) if i else k for k, i in re.findall(r"([A-Za-z_]\w*)|\[(\d+)\]", path))


def _to_theirs(p: Problem, doc: YamlDocument, mapped: Mapped, block: dict[str, Any]) -> Problem:
    """A problem found on our YAML, re-pointed at the key of their file the field came from."""
    loc = _parse_loc(p.path)
    if loc and _lookup(block, loc) is not _MISSING:
        return _at(doc, (BLOCK_KEY, *loc), p)
    for n in range(len(loc), 0, -1):
        hit = mapped.origin.get(format_loc(loc[:n]))
        if hit is not None:
            their_loc, suffix = hit
            return _at(doc, (*their_loc, *(loc[n:] if suffix else ())), p)
    return Problem(str(doc.path), None, None, f"(from the URDF) {p.path}" if p.path else "", p.message, p.severity)


def _at(doc: YamlDocument, loc: Loc, p: Problem) -> Problem:
    return doc.problem(loc, p.message, p.severity)
