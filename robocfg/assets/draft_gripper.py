"""Find the gripper of a URDF for ``robocfg new-robot``: parallel, one-jaw, or the tip of a tool.

All from structure and geometry, never from names. Geometry is measured exactly as
``robocfg validate`` measures it (``robocfg.assets.fingers``: the distal ``PAD_LENGTH`` of each
finger's collision geometry, in the ``ee_link`` frame, metres):

* **parallel** — the non-mimic movable joints below the arm (leaders) move two finger links on
  either side of the approach axis; ``open``/``closed`` are the leader limits with the wider and
  the narrower pad gap;
* **one-jaw** — the arm chain's last joint moves nothing but a leaf link (the jaw) whose pad
  closes onto a link fixed to the joint's parent (the fixed jaw): gap ≤ ``JAW_CONTACT`` at one
  limit and ≥ ``JAW_MIN_OPENING`` at the other. Without this test the jaw reads as a 7th arm joint;
* **TCP** — the pad midpoint with the gripper *closed*, along the approach axis: linkage fingers
  (Robotiq) slide forward as they close, and a small object is held with the fingers almost
  closed (measured on the 2F-85: the open midpoint leaves the pads above a 5 cm cube's centre and
  the grasp fails; the closed one holds). Closed and open agree for sliding fingers (Panda);
* **no gripper joints** — the tool tip: the point of the rigidly attached links' geometry furthest
  along an ee axis (for a suction cup, its face).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robocfg.assets.fingers import (
    FingerGeometryMissing,
    finger_points,
    pad_gap,
    pad_midpoint,
    pad_points,
)
from robocfg.assets.paths import Resolver
from robocfg.assets.urdf import Urdf

AXES = "xyz"
MIN_FINGER_SEPARATION = 0.005  # m: two pads closer than this across the approach axis are one side
JAW_CONTACT = 0.005  # m: a jaw this close to the fixed jaw at one limit closes onto it
JAW_MIN_OPENING = 0.015  # m: ... and opens at least this far at the other limit
MIN_TOOL_TIP = 0.005  # m: a tool tip closer than this to the frame is the frame itself (tcp_offset must be > 0)
PAD_FORCE = 20.0  # N per pad the drafted grip force aims at (a 1 kg object held by friction 0.5 needs 10)


class UnsupportedGripper(Exception):
    """The gripper joints exist but their geometry fits no gripper kind robocfg drafts (the message says why)."""


@dataclass
class GripperDraft:
    """A finger gripper found in the URDF (leader joints and the finger geometry)."""

    kind: str  # "parallel" | "one_jaw"
    joints: list[str]
    open: list[float]
    closed: list[float]
    finger_links: list[str]  # one-jaw: [moving jaw, fixed jaw]
    max_width: float  # m, pad-face gap when open
    min_width: float  # m, pad-face gap when closed
    max_force: float
    closing_axis: str  # ee axis of the closing direction (sign in closing_sign)
    closing_sign: float = 1.0  # -1: the fingers close along −closing_axis (one-jaw only)
    fixed_jaw_face: float | None = None  # m, one-jaw: fixed jaw's face along the closing direction
    max_velocity: float | None = None  # rad/s or m/s: the leaders' URDF velocity limit (None: none given)


@dataclass
class GripperGeometry:
    """What the draft needs besides the gripper block: the approach axis and the TCP distance."""

    gripper: GripperDraft | None
    ee_axis: str
    tcp_offset: float  # m along +ee_axis


def link_points(urdf: Urdf, resolver: Resolver, ee_link: str, links: list[str], q: dict[str, float]) -> dict[str, np.ndarray]:
    """Geometry points (ee_link frame, m) of each of ``links`` that has geometry."""
    T_inv = np.linalg.inv(urdf.link_pose(ee_link, q))
    out = {}
    for ln in links:
        try:
            (P,) = finger_points(urdf, resolver, [ln])
        except FingerGeometryMissing:
            continue
        T = T_inv @ urdf.link_pose(ln, q)
        out[ln] = P @ T[:3, :3].T + T[:3, 3]
    return out


def _approach_axis(clouds: dict[str, np.ndarray]) -> int:
    centroid = np.concatenate(list(clouds.values())).mean(axis=0)
    return int(np.argmax(centroid))


def _pads(urdf: Urdf, resolver: Resolver, ee_link: str, pair: list[str], q: dict[str, float], axis: int) -> list[np.ndarray]:
    return pad_points(urdf, ee_link, pair, finger_points(urdf, resolver, pair), q, axis)


def _lateral(pads: list[np.ndarray], axis: int) -> np.ndarray:
    """Unit vector from pad 0's centre to pad 1's, the approach component removed (zeros if none)."""
    a, b = ((P.min(axis=0) + P.max(axis=0)) / 2 for P in pads)
    d = b - a
    d[axis] = 0.0
    n = np.linalg.norm(d)
    return d / n if n > 1e-9 else d


def _finger_pair(clouds: dict[str, np.ndarray], axis: int) -> list[str]:
    """The link reaching furthest along ``axis`` and the furthest-reaching one across from it."""
    tips = sorted(clouds, key=lambda ln: -clouds[ln][:, axis].max())
    if len(tips) < 2:
        raise UnsupportedGripper(f"the gripper joints move {len(tips)} link(s) with geometry; two fingers are needed")

    def centre(ln: str) -> np.ndarray:
        P = clouds[ln]
        pad = P[P[:, axis] >= P[:, axis].max() - 0.02]
        return (pad.min(axis=0) + pad.max(axis=0)) / 2

    for other in tips[1:]:
        d = centre(other) - centre(tips[0])
        d[axis] = 0.0
        if np.linalg.norm(d) > MIN_FINGER_SEPARATION:
            return [tips[0], other]
    raise UnsupportedGripper(f"no two finger links on either side of the approach axis among {tips}")


def grip_force(urdf: Urdf, ee_link: str, leaders: list[str], pads: list[np.ndarray], q: dict[str, float]) -> float:
    """Drive force (N) or torque (N·m) per leader that presses each pad with about ``PAD_FORCE``:
    a prismatic leader pushes ``PAD_FORCE``; a revolute one ``PAD_FORCE`` × the lever from its axis
    to the pads (ee frame, at ``q``); plus the joint's ``<dynamics>`` friction and its damping at
    the rated velocity. Capped by the URDF effort, which is often a motor's stall
    value: 1000 N·m on the airo-models 2F-85, whose linkage tilts its fingers above ≈ 3 N·m."""
    centres = [(P.min(axis=0) + P.max(axis=0)) / 2 for P in pads]
    T_ee_inv = np.linalg.inv(urdf.link_pose(ee_link, q))
    out = []
    for name in leaders:
        j = urdf.joints[name]
        if j.type == "prismatic":
            f = PAD_FORCE
        else:
            T = T_ee_inv @ urdf.link_pose(j.parent, q) @ j.origin
            a, o = T[:3, :3] @ j.axis, T[:3, 3]
            lever = max(float(np.linalg.norm(np.cross(c - o, a))) for c in centres)
            f = PAD_FORCE * max(lever, 0.01)
        # What the joint's own <dynamics> take before the pads feel anything: its friction, and
        # its damping at the rated speed (Unitree Z1's jaw: 1 N·m + 1 N·m·s/rad × 3.14 rad/s).
        f += j.friction + j.damping * j.velocity
        out.append(min(f, j.effort) if j.effort > 0 else f)
    return round(float(min(out)), 3)


def rated_velocity(urdf: Urdf, leaders: list[str]) -> float | None:
    """The slowest leader's URDF velocity limit (rad/s or m/s), or None when none gives one.

    The draft caps the gripper drive with it: PyBullet's position drive otherwise asks for
    (stiffness / timestep) × error — 12.7 rad/s for the Z1 jaw 0.5 rad from its target — and a
    joint's ``<dynamics>`` damping at that speed (1 N·m·s/rad there) takes more than the whole
    drive force, so the jaw stalls half-way (it never reopened after a grasp)."""
    rated = [urdf.joints[j].velocity for j in leaders if urdf.joints[j].velocity > 0]
    return round(float(min(rated)), 6) if rated else None


def _limits(urdf: Urdf, leaders: list[str]) -> tuple[dict[str, float], dict[str, float]]:
    return ({j: urdf.joints[j].lower for j in leaders}, {j: urdf.joints[j].upper for j in leaders})


def parallel_gripper(urdf: Urdf, resolver: Resolver, ee_link: str, leaders: list[str]) -> GripperGeometry:
    """Two fingers moved by ``leaders`` (and their mimic followers). Raises UnsupportedGripper."""
    followers = [j.name for j in urdf.joints.values() if j.mimic is not None and j.mimic.joint in leaders]
    moved = set().union(*(urdf.descendants(j) for j in leaders + followers))
    leaves = sorted(ln for ln in moved if not any(j.parent == ln for j in urdf.joints.values()))
    lo, hi = _limits(urdf, leaders)
    clouds = link_points(urdf, resolver, ee_link, leaves, lo)
    if len(clouds) < 2:
        raise UnsupportedGripper(f"gripper joints {leaders} move {len(clouds)} link(s) with geometry; two fingers are needed")
    axis = _approach_axis(clouds)
    pair = _finger_pair(clouds, axis)
    gaps = []
    for q in (lo, hi):
        pads = _pads(urdf, resolver, ee_link, pair, q, axis)
        gaps.append(pad_gap(pads, _lateral(pads, axis)))
    open_q, closed_q = (hi, lo) if gaps[1] > gaps[0] else (lo, hi)
    closed_pads = _pads(urdf, resolver, ee_link, pair, closed_q, axis)
    open_pads = _pads(urdf, resolver, ee_link, pair, open_q, axis)
    c = _lateral(open_pads, axis)
    closing = int(np.argmax(np.abs(c)))
    if closing == axis:
        closing = (axis + 1) % 3
    tcp = float(pad_midpoint(closed_pads)[axis])
    g = GripperDraft("parallel", leaders, [round(open_q[j], 6) for j in leaders], [round(closed_q[j], 6) for j in leaders],
                     pair, round(max(max(gaps), 1e-3), 4), round(max(min(gaps), 0.0), 4),
                     grip_force(urdf, ee_link, leaders, closed_pads, closed_q), AXES[closing],
                     max_velocity=rated_velocity(urdf, leaders))
    return GripperGeometry(g, AXES[axis], tcp)


def one_jaw_gripper(urdf: Urdf, resolver: Resolver, chain: list[str], ee_link: str) -> GripperGeometry | None:
    """The one-jaw gripper whose jaw is ``chain[-1]``, or None when that joint is not a jaw."""
    jaw = urdf.joints[chain[-1]]
    moved = urdf.descendants(jaw.name)
    if any(j.movable for j in urdf.joints.values() if j.parent in moved):
        return None
    lo, hi = _limits(urdf, [jaw.name])
    fixed_cands = [jaw.parent] + [j.child for j in urdf.joints.values() if j.parent == jaw.parent and not j.movable]
    moving = link_points(urdf, resolver, ee_link, sorted(moved), lo)
    fixed = link_points(urdf, resolver, ee_link, fixed_cands, lo)
    if not moving or not fixed:
        return None
    axis = _approach_axis({**moving, **fixed})
    jaw_link = max(moving, key=lambda ln: moving[ln][:, axis].max())
    fixed_link = max(fixed, key=lambda ln: fixed[ln][:, axis].max())
    pair = [jaw_link, fixed_link]
    for closed_q, open_q in ((lo, hi), (hi, lo)):
        found = _jaw_at(urdf, resolver, ee_link, jaw.name, pair, closed_q, open_q, axis)
        if found is not None:
            return found
    return None


def jaw_opening(urdf: Urdf, ee_link: str, jaw_link: str, moving_pad: np.ndarray, q_from: dict[str, float],
                q_to: dict[str, float]) -> np.ndarray:
    """The moving jaw's pad points (ee_link frame) carried rigidly from joint values ``q_from`` to
    ``q_to``: a revolute jaw's tip swings away, which the distal part re-measured at ``q_to`` (the
    jaw's side, once it has turned) would not show."""
    def pose(q: dict[str, float]) -> np.ndarray:
        return np.linalg.inv(urdf.link_pose(ee_link, q)) @ urdf.link_pose(jaw_link, q)

    T = pose(q_to) @ np.linalg.inv(pose(q_from))
    return moving_pad @ T[:3, :3].T + T[:3, 3]


def _jaw_at(urdf: Urdf, resolver: Resolver, ee_link: str, joint: str, pair: list[str], closed_q: dict[str, float],
            open_q: dict[str, float], axis: int) -> GripperGeometry | None:
    """The one-jaw gripper if the jaw touches the fixed jaw at ``closed_q`` and opens at ``open_q``."""
    pads = _pads(urdf, resolver, ee_link, pair, closed_q, axis)
    c = _lateral(pads, axis)  # moving pad → fixed pad: the closing direction
    if not np.linalg.norm(c):
        return None
    gap_closed = pad_gap(pads, c)
    gap_open = pad_gap([jaw_opening(urdf, ee_link, pair[0], pads[0], closed_q, open_q), pads[1]], c)
    if gap_closed > JAW_CONTACT or gap_open < JAW_MIN_OPENING:
        return None
    closing = int(np.argmax(np.abs(c)))
    if closing == axis:
        return None
    sign = float(np.sign(c[closing]))
    unit = np.zeros(3)
    unit[closing] = sign
    face = float((pads[1] @ unit).min())
    tcp = float(pad_midpoint(pads)[axis])
    g = GripperDraft("one_jaw", [joint], [round(open_q[joint], 6)], [round(closed_q[joint], 6)], pair,
                     round(gap_open, 4), round(max(gap_closed, 0.0), 4), grip_force(urdf, ee_link, [joint], pads, closed_q), AXES[closing],
                     sign, round(face, 4), rated_velocity(urdf, [joint]))
    return GripperGeometry(g, AXES[axis], tcp)


def tool_tip(urdf: Urdf, resolver: Resolver, cands: list[str]) -> tuple[GripperGeometry, str, str] | None:
    """The tip of a tool without gripper joints, for a suction cup its face: (ee axis and distance
    to it, the ee_link frame it is measured in, the link it belongs to), or None without geometry.

    ``cands`` are the links rigid with the last arm joint, ``cands[0]`` the wrist link. The tip is
    the point of their geometry furthest from the wrist's origin (a cup past the fingers of a
    Kinova hand, the cup of a KR 210's tool). Its frame is the deepest link on the way to it along
    one of whose + axes it lies (within half its distance of the axis line): a cup link whose
    origin is its own face cannot measure it."""
    wrist = cands[0]
    clouds = link_points(urdf, resolver, wrist, cands, {})
    if not clouds:
        return None
    owners = [ln for ln, P in clouds.items() for _ in range(len(P))]
    P = np.concatenate(list(clouds.values()))
    i = int(np.argmax(np.linalg.norm(P, axis=1)))
    owner = owners[i]
    path = [ln for ln in cands if urdf.chain(ln, owner) is not None]
    for frame in sorted(path, key=lambda ln: -len(urdf.chain(wrist, ln) or [])):
        T = np.linalg.inv(urdf.link_pose(frame)) @ urdf.link_pose(wrist)
        p = T[:3, :3] @ P[i] + T[:3, 3]
        k = int(np.argmax(p))
        tip, lateral = float(p[k]), float(np.linalg.norm(np.delete(p, k)))
        if tip > MIN_TOOL_TIP and lateral <= 0.5 * tip:
            return GripperGeometry(None, AXES[k], tip), frame, owner
    return None
