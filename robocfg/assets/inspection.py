"""Joint table and EE-link candidates of a URDF (what ``robocfg inspect`` shows)."""

from __future__ import annotations

from dataclasses import dataclass

from robocfg.assets.urdf import Urdf


@dataclass(frozen=True)
class JointRow:
    name: str
    type: str
    parent: str
    child: str
    dof_index: int | None
    pybullet_index: int
    lower: float
    upper: float
    velocity: float
    mimic: str | None
    movable: bool


@dataclass(frozen=True)
class UrdfInfo:
    joints: list[JointRow]
    ee_candidates: list[str]
    arm_chain: list[str]


def inspect_urdf(urdf: Urdf) -> UrdfInfo:
    rows = []
    for j in sorted(urdf.joints.values(), key=lambda j: j.urdf_index):
        mimic = None
        if j.mimic is not None:
            mimic = f"{j.mimic.multiplier:g}·{j.mimic.joint} + {j.mimic.offset:g}"
        rows.append(JointRow(j.name, j.type, j.parent, j.child, urdf.dof_joints.index(j.name) if j.movable else None,
                             j.urdf_index, j.lower, j.upper, j.velocity, mimic, j.movable))
    chain = longest_serial_chain(urdf)
    return UrdfInfo(rows, ee_candidates(urdf, chain), chain)


def longest_serial_chain(urdf: Urdf) -> list[str]:
    """Names of the longest root-to-leaf sequence of non-mimic movable joints (the arm, usually)."""
    best: list[str] = []

    def visit(link: str, acc: list[str]) -> None:
        nonlocal best
        kids = [j for j in urdf.joints.values() if j.parent == link]
        if len(acc) > len(best):
            best = list(acc)
        for j in kids:
            moving = j.movable and j.mimic is None
            visit(j.child, [*acc, j.name] if moving else acc)

    visit(urdf.root, [])
    # stop the chain where it branches into a gripper: drop trailing joints whose parent has >1 moving child
    while len(best) > 1:
        parent = urdf.joints[best[-1]].parent
        siblings = [j for j in urdf.joints.values() if j.parent == parent and j.movable]
        if len(siblings) > 1 or _has_movable_sibling_branch(urdf, best[-1]):
            best = best[:-1]
        else:
            break
    return best


def _has_movable_sibling_branch(urdf: Urdf, joint: str) -> bool:
    j = urdf.joints[joint]
    # a prismatic joint at the end of a chain whose parent also carries a mimic follower is a finger
    return any(k.mimic is not None and k.mimic.joint == joint for k in urdf.joints.values()) and j.type == "prismatic"


def ee_candidates(urdf: Urdf, chain: list[str]) -> list[str]:
    """Links rigidly attached (fixed joints only) to the last joint of ``chain``."""
    if not chain:
        return []
    start = urdf.joints[chain[-1]].child
    out, stack = [start], [start]
    while stack:
        cur = stack.pop()
        for j in urdf.joints.values():
            if j.parent == cur and not j.movable:
                out.append(j.child)
                stack.append(j.child)
    return out
