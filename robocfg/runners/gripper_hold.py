"""The hold test of ``run gripper``: the task's ``hold_object`` placed between the fingers (or
against a suction cup) on a static support made for it, gripped, the support lowered by
``lift_support_by`` (0 removes it), held for ``HOLD_WAIT``, then released. Fails with
``RunFailed(phase, reason)`` at the first check that does not pass. World frame, m, s.
"""

from __future__ import annotations

import numpy as np

from robocfg.config.scene import Body
from robocfg.errors import RunFailed
from robocfg.runners.gripper_report import HoldTest, _mm
from robocfg.runners.gripper_run import SETTLE_TIME, GripperRun

HOLD_DROP_MAX = 0.01  # m: the object may sink this much and still count as held
SUPPORT_LOWER_TIME = 0.5  # s
HOLD_WAIT = 0.5  # s after the support has gone


def _place_object(run: GripperRun, at: np.ndarray, R: np.ndarray):
    """Move the hold object to ``at`` with rotation ``R`` on a static support; returns (name, body, support Body)."""
    from robocfg.geometry import matrix_to_quat

    w, name = run.world, run.params.hold_object
    if name is None:
        raise RunFailed("place", "no gripper.hold_object to place")
    spec = next((b for b in w.task.config.scene.objects if b.name == name), None)
    if spec is None:
        known = [b.name for b in w.task.config.scene.objects]
        raise RunFailed("place", f"hold_object {name!r} is not in scene.objects (known: {', '.join(known) or 'none'})")
    w.set_body_pose(name, at, matrix_to_quat(R))
    bottom = at[2] - _half_extent_z(w, name)
    top_size = 0.6 * min(_footprint(spec))
    support = Body(name="_support", shape="box", size=[top_size, top_size, max(bottom, 0.01)], mass=0.0,
                   color=[0.4, 0.4, 0.45, 1.0], position=[float(at[0]), float(at[1]), bottom - max(bottom, 0.01) / 2])
    w.add_body(support, static=True)
    return name, support


def _grasp_centre(run: GripperRun, tcp: np.ndarray) -> np.ndarray:
    """Where the hold object's centre goes: the TCP, moved across by ``grasp_side_shift`` at the
    object's width along the closing direction (a one-jaw gripper holds it against its fixed jaw)."""
    from robocfg.kinematics.frames import grasp_side_shift

    cfg = run.arm.config
    spec = next((b for b in run.world.task.config.scene.objects if b.name == run.params.hold_object), None)
    closing_ee = np.asarray(cfg.R_ee_graspnet, float)[1]
    if spec is None:
        return tcp[:3, 3]
    k = int(np.argmax(np.abs(closing_ee)))
    width = float(spec.size[k]) if spec.shape == "box" else 2 * float(spec.size[0])
    return tcp[:3, 3] + grasp_side_shift(cfg, width) * (tcp[:3, :3] @ closing_ee)


def _half_extent_z(world, name: str) -> float:
    lo, hi = world.aabb(name)
    return float(hi[2] - lo[2]) / 2


def _footprint(b: Body) -> list[float]:
    if b.shape in ("box", "mesh"):
        return [b.size[0], b.size[1]]
    return [2 * b.size[0], 2 * b.size[0]]


def _lower_support(run: GripperRun, support: Body) -> None:
    w, by = run.world, run.params.lift_support_by
    if by <= 0:
        w.remove_body(support.name)
        return
    x, y, z0 = support.position
    n = max(1, round(SUPPORT_LOWER_TIME / w.dt))
    k = [0]

    def lower() -> None:
        k[0] += 1
        w.set_body_pose(support.name, [x, y, z0 - by * min(1.0, k[0] / n)])

    run.run_for(SUPPORT_LOWER_TIME, each=lower)


def _support_away(run: GripperRun, hold: HoldTest, support: Body, z0: float) -> None:
    """Lower (or remove) the support, wait ``HOLD_WAIT``, and record in ``hold`` how far the object
    sank below ``z0`` (its centre's height when gripped, m) and whether it is still gripped."""
    _lower_support(run, support)
    run.phase("hold")
    run.run_for(HOLD_WAIT)
    hold.drop = float(z0 - run.world.body_pose(hold.object)[0][2])
    hold.grasping_after = run.gripper.is_grasping(hold.object)
    hold.held = hold.grasping_after and hold.drop < HOLD_DROP_MAX


def hold_test(run: GripperRun) -> None:
    """Parallel (and one-jaw) grippers: the object is placed between the open fingers, gripped,
    the support lowered, then released."""
    w, g, res = run.world, run.gripper, run.result
    tcp = run.arm.tcp_pose()
    name, support = _place_object(run, _grasp_centre(run, tcp), run.arm.ee_pose()[:3, :3])
    run.run_for(SETTLE_TIME)
    run.move("grasp", 0, g.close)
    grasp_before = g.is_grasping(name)
    width_on = run.width()
    z0 = w.body_pose(name)[0][2]
    hold = HoldTest(name, run.params.lift_support_by, grasp_before, False, width_on, 0.0, False, False)
    res.hold = hold
    if not grasp_before:
        raise RunFailed("grasp", f"the fingers do not both touch {name!r} after closing (width {_mm(width_on)})")
    _support_away(run, hold, support, z0)
    if not hold.held:
        raise RunFailed("hold", f"{name!r} was not held: it sank {hold.drop * 1000:.1f} mm "
                                f"(limit {HOLD_DROP_MAX * 1000:.0f} mm), fingers touching: {hold.grasping_after}")
    run.move("release", 0, g.open)
    hold.released = not g.is_grasping(name)
    if not hold.released:
        raise RunFailed("release", f"{name!r} still between both fingers after opening")


def suction_test(run: GripperRun) -> None:
    """Suction: the object is placed against the cup, suction on, support lowered, suction off."""
    w, g, res = run.world, run.gripper, run.result
    run.run_for(SETTLE_TIME)
    if not run.params.hold_object:
        raise RunFailed("place", "a suction gripper needs gripper.hold_object to test")
    cup = run.world.robot.link_pose(g.config.link)
    name = run.params.hold_object
    down = cup[:3, 2]  # the cup's z axis points out of the cup face
    w.set_body_pose(name, cup[:3, 3])  # provisional, then push it out by its half extent
    at = cup[:3, 3] + down * _half_extent_z(w, name)
    name, support = _place_object(run, at, np.eye(3))
    run.run_for(SETTLE_TIME)
    z0 = w.body_pose(name)[0][2]
    run.move("grasp", 0, g.on)
    hold = HoldTest(name, run.params.lift_support_by, g.is_grasping(name), False, None, 0.0, False, False)
    res.hold = hold
    if not hold.grasping_before:
        raise RunFailed("grasp", f"suction did not attach {name!r}")
    _support_away(run, hold, support, z0)
    if not hold.held:
        raise RunFailed("hold", f"{name!r} was not held (sank {hold.drop * 1000:.1f} mm)")
    run.move("release", 0, g.off)
    hold.released = not g.is_grasping(name)
