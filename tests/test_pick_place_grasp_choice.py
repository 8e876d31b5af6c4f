"""The grasp choice checks candidates' straight lines lazily: the same grasp as checking them all."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest

from robocfg.checks import load_task
from robocfg.config import catalog
from robocfg.engine import RunOptions, open_session
from robocfg.errors import PhaseFailed
from robocfg.geometry import rotation_angle
from robocfg.kinematics.frames import ee_pose_from_grasp
from robocfg.runners.pick_place_grasp_choice import shifted
from robocfg.runners.pick_place_machine import _StateMachine


def _exhaustive(m: _StateMachine, lying):
    """The rule as it was written before: every candidate's travel and both of its lines, then
    the least (broken, travel), ties to the smaller wrist turn. Returns (that grasp, the grasp
    of least travel whatever its lines)."""
    R_now, q0 = m.arm.ee_pose()[:3, :3], m.arm.joint_positions()
    for group in m._iter_grasp_groups(lying):
        cands = sorted(group, key=lambda g: rotation_angle(R_now, g.rotation @ np.asarray(m.cfg.R_ee_graspnet)))

        def travel(g):
            shift = np.array([*(m.setup.place_xy - g.center[:2]), 0.0])
            T_pre = ee_pose_from_grasp(g, m.cfg, standoff=m.params.above_height)
            T_grasp = ee_pose_from_grasp(g, m.cfg)
            cost, q, broken = 0.0, q0, False
            for T, T_down in ((T_pre, T_grasp), (shifted(T_pre, shift), shifted(T_grasp, shift))):
                res = m.model.ik(T, seed_q=q, frame="ee", time_budget=m.mover.ik_budget)
                if not res.converged:
                    return True, math.inf
                cost, q = max(cost, float(np.max(np.abs(res.q - q)))), res.q
                broken = broken or not m._line_continuous(q, T_down)
            return broken, cost

        costs = [travel(g) for g in cands]
        if min(c for _, c in costs) < math.inf:
            best = min(range(len(cands)), key=lambda i: costs[i])
            cheapest = min(range(len(cands)), key=lambda i: costs[i][1])
            return cands[best], cands[cheapest]
    return None, None


def _some_lines_broken(self, q, T_down) -> bool:
    """A stand-in line check for both rules alike: a third of the lines "break", by a
    checksum of the line's end pose (real breaks are rare: none in 240 default episodes on 8 robots)."""
    return zlib.crc32(np.round(T_down, 9).tobytes()) % 3 != 0


@pytest.mark.parametrize(("robot", "arm", "episodes", "breaks"), [
    (None, None, range(6), False),
    (None, None, range(10), True),
    ("ur5e_robotiq_2f85", None, range(3), False),
    ("xarm6", None, range(4), True),
    ("dual_panda", "right", [26], False),  # the smaller wrist turn's IK lands on a flipped shoulder
])
def test_lazy_grasp_choice_is_the_exhaustive_choice(monkeypatch, robot, arm, episodes, breaks):
    chosen, solves = [], {"lazy": 0, "all": 0}
    lazy = _StateMachine._choose_grasp
    if breaks:
        monkeypatch.setattr(_StateMachine, "_line_continuous", _some_lines_broken)

    def both(self, lying):
        ik, count = self.model.ik, {"n": 0}

        def counted(*a, **k):
            count["n"] += 1
            return ik(*a, **k)

        self.model.ik = counted
        try:
            g = lazy(self, lying)
            solves["lazy"] += count["n"]
            count["n"] = 0
            self.mover._answers.clear()  # the mover remembers answers: the reference asks afresh
            ref, cheapest = _exhaustive(self, lying)
            solves["all"] += count["n"]
        finally:
            del self.model.ik
        chosen.append((g, ref, cheapest))
        raise PhaseFailed("grasp_choice", "compared; the episode ends here")

    monkeypatch.setattr(_StateMachine, "_choose_grasp", both)
    task = load_task(catalog.find("tasks", "pick_place"), robot_override=robot)
    with open_session(task, RunOptions(seed=0, arm=arm)) as session:
        for k in episodes:
            session.run(k)
    assert len(chosen) == len(episodes)
    for g, ref, _ in chosen:
        assert ref is not None
        assert np.array_equal(g.center, ref.center) and np.array_equal(g.rotation, ref.rotation)
    if not breaks:  # the point of it: lines (IK every 3 cm) of candidates that cannot win are skipped
        assert solves["lazy"] < solves["all"]
    else:  # the stand-in breaks made a costlier candidate win at least once
        assert any(not np.array_equal(g.rotation, cheapest.rotation) for g, _, cheapest in chosen)
