"""Loading a robot into placo for the reactive controller: the URDF text without geometry (the
controller brings its own convex hulls) and a guard that silences placo's C++ prints.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

CONTINUOUS_RANGE = 1000.0  # rad: limits written on continuous joints for placo (its own joint limits are off)


def urdf_without_geometry(path: Path) -> str:
    """The URDF text without ``<visual>``/``<collision>`` elements (placo then loads no meshes), fixed
    joints named like a link renamed (Unitree's Z1 has a link and a joint ``gripperStator``), and
    with continuous joints made revolute: pinocchio gives a continuous joint two coordinates
    (cos, sin), this controller one angle per joint. The angle is left unwrapped (the box bounds of
    a continuous joint are infinite), so a joint that turns past ±π keeps turning smoothly."""
    import xml.etree.ElementTree as ET

    from robocfg.assets.urdf_xml import revolute_continuous

    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for el in link.findall(tag):
                link.remove(el)
    links = {link.get("name") for link in root.iter("link")}
    for joint in root.iter("joint"):
        if joint.get("type") == "fixed" and joint.get("name") in links:  # placo cannot tell a link from a joint of the same name
            joint.set("name", f"{joint.get('name')}__fixed_joint")
    revolute_continuous(root, CONTINUOUS_RANGE)
    return ET.tostring(root, encoding="unicode")


@contextlib.contextmanager
def quiet_stdout():
    """Silence C++ prints (placo warns on stdout while loading)."""
    import os
    import sys

    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
