"""Free-space points of a task written for one robot, mapped to the robot that runs it
(``placement: auto`` of the trajectory and follow-target tasks).

A task's Cartesian points (trajectory waypoints, the follow-target motion and its obstacles) are
world coordinates written for the robot the file names. When the running robot (``--robot``)
reaches every one of them with the task's tool orientation (IK), nothing changes. When it does
not, the points are moved with the arm: ``p' = b_run + k · (p − b_task)``, with ``b`` the world
position of each arm's ``base_link`` (at its home pose) and ``k`` the ratio of the two arms'
reaches along the direction from the arm base to the points' middle (the farthest distance at
which IK reaches the TCP with the tool orientation of the first point). Lengths (radius, obstacle
sizes) are scaled by ``k``. A desk arm's points thus land where a KR 210 on the floor, or an arm
mounted high on a torso lift, works.

The mapped points are checked too: an arm's reachable set along a ray is not always one interval
(the drafted Unitree Z1 with its tool pointing down reaches 0.2-0.3 m and 0.8 m along the default
trajectory's direction, not 0.35-0.75 m), and along a ray the arm reaches nowhere there is no
ratio at all (then 1). When some mapped point is out of IK reach, ``k`` steps down (``SHRINK``
times the ratio) until every point is reached; when none works the points are left for the run
to report unreachable. A runner may ask more of each IK answer than reaching (``accept``):
follow-target asks for the reactive controller's margins (see ``robocfg.runners.follow_target``),
because IK reached every point of the IRB 7600's circle at x0.9 where the controller then stalled
at its 20 mm self-collision margin (upper arm against the wrist, RMS 50 mm).

Frames: world, metres.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from robocfg.checks.robot import CheckedRobot, load_robot
from robocfg.checks.task import CheckedTask
from robocfg.geometry import pose_matrix
from robocfg.kinematics.frames import tool_R_ee
from robocfg.motion.placement import farthest_reachable

FK_SAMPLES = 400  # random configurations bounding how far the TCP can get from the arm base
IK_BUDGET = 0.2  # s per IK query; not consulted: bound_ik_by_iterations ends the search by count
# Fractions of the reach ratio tried, largest first, in 0.05 steps: reachability along the scale
# is not monotonic (the IRB 7600's default circle: IK reaches every point at x0.95, not at x0.9,
# x0.8 or x0.7), and a coarser step gives away up to a tenth of the task's size.
SHRINK = tuple(round(1.0 - 0.05 * i, 2) for i in range(15))  # 1.0 ... 0.3


@dataclass(frozen=True)
class PointMap:
    """``p' = to + scale · (p − origin)`` (m, world), with the line saying so (``note``)."""

    origin: np.ndarray
    to: np.ndarray
    scale: float
    note: str

    def point(self, p: Sequence[float]) -> list[float]:
        return [float(v) for v in self.to + self.scale * (np.asarray(p, float) - self.origin)]

    def length(self, x: float) -> float:
        return float(self.scale * x)


def auto_map(task: CheckedTask, arm: str | None, poses: list[np.ndarray], what: str,
             frame: str = "ee_link", accept: Callable[[np.ndarray], bool] | None = None) -> PointMap | None:
    """The map for ``poses`` (4x4 world_T_tcp targets of the running robot's ``arm``, its TCP frame
    having ee_link's rotation), or None when that arm reaches every one, the file names the running
    robot itself, or no reach can be measured (the run then reports the unreachable points itself).
    ``frame``: what the task's orientations were written in; with ``tool`` the task's robot is
    measured with the same *tool* orientation (converted through each robot's ``R_ee_graspnet``),
    with ``ee_link`` with the same ee_link rotation. ``accept``: what the runner needs of an IK
    answer (joint values, arm order) besides reaching, e.g. the controller's margins; a point
    whose answer it refuses counts as not reached (the reach ratio itself is measured by IK)."""
    ours_robot = task.robots[0]
    ours = _model(task, ours_robot, arm)
    if all(_reaches(ours, ours_robot, arm, T, accept) for T in poses):
        return None
    written = task.written_robot
    if written is None or written.resolve() == ours_robot.path.resolve():
        return None
    theirs_robot = load_robot(written)
    theirs = _model(task, theirs_robot, None)
    b_theirs, b_ours = _arm_base(theirs, theirs_robot, None), _arm_base(ours, ours_robot, arm)
    middle = np.mean([T[:3, 3] for T in poses], axis=0)
    direction = middle - b_theirs
    if np.linalg.norm(direction) < 1e-6:
        return None
    direction /= np.linalg.norm(direction)
    R = poses[0][:3, :3]
    R_theirs = R
    to_ours, to_theirs = tool_R_ee(ours_robot.config.arm(arm)), tool_R_ee(theirs_robot.config.arm(None))
    if frame == "tool" and not np.array_equal(to_ours, to_theirs):  # the same tool orientation on the task's robot
        R_theirs = R @ to_ours.T @ to_theirs
    r_theirs = _reach(theirs, theirs_robot, None, b_theirs, direction, R_theirs)
    r_ours = _reach(ours, ours_robot, arm, b_ours, direction, R)
    measured = r_theirs > 0.0 and r_ours > 0.0
    ratio = r_ours / r_theirs if measured else 1.0
    for f in SHRINK:
        m = PointMap(b_theirs, b_ours, ratio * f, "")
        if all(_reaches(ours, ours_robot, arm, _moved(T, m), accept) for T in poses):
            break
    else:
        return None  # no scale reaches them all: the run names the unreachable points
    how = (f"reach {r_ours:.2f} m, the task's robot {theirs_robot.config.name}: {r_theirs:.2f} m" if measured
           else "no reach measured along the points' direction")
    kept = "" if accept is None else " keeping the controller's margins"
    how += "" if f == 1.0 else f"; x{f:g} of {ratio:.2f}, the largest step at which IK reaches every point{kept}"
    note = (f"placement auto: {what} moved to {ours_robot.config.name}'s arm ({how}): scaled x{m.scale:.2f} about its "
            f"base at [{b_ours[0]:.3f}, {b_ours[1]:.3f}, {b_ours[2]:.3f}] m")
    return PointMap(b_theirs, b_ours, m.scale, note)


def _moved(T: np.ndarray, m: PointMap) -> np.ndarray:
    """``T`` with its position mapped by ``m``."""
    out = T.copy()
    out[:3, 3] = m.to + m.scale * (T[:3, 3] - m.origin)
    return out


def _model(task: CheckedTask, robot: CheckedRobot, arm: str | None):
    from robocfg.kinematics.model import KinematicModel
    from robocfg.motion.moves import bound_ik_by_iterations

    model = KinematicModel.from_robot(robot, arm=robot.config.arm(arm).name, base_pose=pose_matrix(task.config.robots[0]))
    bound_ik_by_iterations(model)  # same answers whatever the machine load
    return model


def _reaches(model, robot: CheckedRobot, arm: str | None, T: np.ndarray,
             accept: Callable[[np.ndarray], bool] | None = None) -> bool:
    home = np.asarray(robot.config.arm(arm).home, float)
    res = model.ik(T, seed_q=home, frame="tcp", time_budget=IK_BUDGET)
    return bool(res.converged) and (accept is None or bool(accept(np.asarray(res.q, float))))


def _arm_base(model, robot: CheckedRobot, arm: str | None) -> np.ndarray:
    """World position (m) of the arm's base_link at its home pose."""
    arm_cfg = robot.config.arm(arm)
    return model.fk(np.asarray(arm_cfg.home, float), arm_cfg.base_link)[:3, 3].copy()


def _reach(model, robot: CheckedRobot, arm: str | None, base: np.ndarray, direction: np.ndarray, R: np.ndarray) -> float:
    """The farthest distance (m) from ``base`` along ``direction`` at which IK puts the TCP with
    rotation ``R``; 0 when none of the distances tried is reached."""
    rng = np.random.default_rng(0)
    q = rng.uniform(model.lower, model.upper, size=(FK_SAMPLES, len(model.lower)))
    far = max(float(np.linalg.norm(model.fk(qi, "tcp")[:3, 3] - base)) for qi in q)

    def ok(d: float) -> bool:
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, base + d * direction
        return _reaches(model, robot, arm, T)

    return farthest_reachable(ok, far)
