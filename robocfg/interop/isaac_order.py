"""Isaac Sim's articulation DOF order, computed from a URDF.

PhysX numbers an articulation's degrees of freedom breadth-first from the root link (all joints
one level down, then the next level), whereas the URDF file order — robocfg's DOF indices, and
PyBullet's — is depth-first. On a serial arm the two agree; on a dual-arm robot the left and right
joints interleave (left joint 1 = 0, right joint 1 = 1, ...), and on grippers with several finger
branches they differ too. Sibling joints keep their URDF file order (the URDF importer creates the
prims in that order).
"""

from __future__ import annotations

from collections import deque

from robocfg.assets.urdf import Urdf


def isaac_dof_order(urdf: Urdf) -> list[str]:
    """Movable joint names in Isaac articulation DOF order (index = position in the list)."""
    children: dict[str, list] = {}
    for j in sorted(urdf.joints.values(), key=lambda j: j.urdf_index):
        children.setdefault(j.parent, []).append(j)
    order: list[str] = []
    queue = deque([urdf.root])
    while queue:
        for j in children.get(queue.popleft(), []):
            if j.movable:
                order.append(j.name)
            queue.append(j.child)
    return order
