"""Local-minimum escape rule: stall detection, via-point directions, give-up after max_attempts."""

from __future__ import annotations

import numpy as np

from robocfg.motion.reactive.escape import Blocking, EscapeRule, EscapeSettings

DT = 1.0 / 240.0
MARGIN = 0.02


def _run(rule: EscapeRule, tcp, target, blocking, seconds: float, t0: float = 0.0):
    """Feed a TCP that does not move; returns (time, tracked point) at the first change, else the last."""
    t, out = t0, target
    for _ in range(round(seconds / DT)):
        t += DT
        out = rule.update(t, np.asarray(tcp), np.asarray(target), blocking)
        if not np.allclose(out, target):
            return t, out
    return t, out


def test_head_on_stall_goes_over_the_obstacle():
    rule = EscapeRule(EscapeSettings(), MARGIN)
    tcp, target = np.array([0.3, 0.0, 0.4]), np.array([0.6, 0.0, 0.4])
    blocking = [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))]  # obstacle straight ahead
    t, via = _run(rule, tcp, target, blocking, 1.0)
    assert rule.active and rule.count == 1
    assert t >= EscapeSettings().stall_time  # waited for the stall first
    assert via[2] > tcp[2] + 0.05  # over
    assert via[0] <= tcp[0] + 1e-9  # not into the obstacle


def test_slides_along_the_tangent_when_not_head_on():
    rule = EscapeRule(EscapeSettings(), MARGIN)
    tcp, target = np.array([0.3, 0.0, 0.4]), np.array([0.5, 0.3, 0.4])
    blocking = [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))]
    _, via = _run(rule, tcp, target, blocking, 1.0)
    step = via - tcp
    assert step[1] > 0.1  # along +y, the target's side
    assert abs(step[0]) < 0.03  # stays on the tangent plane (plus the small offset along n)


def test_no_escape_without_a_blocking_pair_or_when_reached():
    rule = EscapeRule(EscapeSettings(), MARGIN)
    tcp, target = np.array([0.3, 0.0, 0.4]), np.array([0.6, 0.0, 0.4])
    _, out = _run(rule, tcp, target, [], 1.0)  # stuck, but nothing blocks (e.g. out of reach)
    assert not rule.active and np.allclose(out, target)
    far = [Blocking(0.2, np.array([-1.0, 0.0, 0.0]))]
    _run(rule, tcp, target, far, 1.0)
    assert not rule.active
    _run(rule, target + 0.001, target, [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))], 1.0)
    assert not rule.active  # within min_error: reached, not stalled


def test_gives_up_after_max_attempts_instead_of_thrashing():
    s = EscapeSettings(max_time=0.05)
    rule = EscapeRule(s, MARGIN)
    tcp, target = np.array([0.3, 0.0, 0.4]), np.array([0.6, 0.0, 0.4])
    blocking = [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))]
    t = 0.0
    vias = []
    for _ in range(round(10.0 / DT)):
        t += DT
        out = rule.update(t, tcp, target, blocking)
        if rule.active and (not vias or not np.allclose(vias[-1], out)):
            vias.append(out)
    assert rule.count == s.max_attempts
    assert len({tuple(np.round(v, 6)) for v in vias}) == s.max_attempts  # each attempt tries something new


def test_disabled_rule_passes_the_target_through():
    rule = EscapeRule(EscapeSettings(enabled=False), MARGIN)
    _, out = _run(rule, [0.3, 0.0, 0.4], [0.6, 0.0, 0.4], [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))], 1.0)
    assert np.allclose(out, [0.6, 0.0, 0.4]) and rule.count == 0


def test_target_against_the_environment_is_held_not_escaped():
    rule = EscapeRule(EscapeSettings(), MARGIN)
    rule.clearance_fn = lambda p: 0.01  # the target sits 1 cm from the table: no detour reaches it
    tcp, target = np.array([0.5, 0.0, 0.25]), np.array([0.5, 0.0, 0.17])
    _, out = _run(rule, tcp, target, [Blocking(MARGIN, np.array([0.0, 0.0, 1.0]))], 2.0)
    assert rule.count == 0 and rule.blocked_target and np.allclose(out, target)


def test_a_moved_target_starts_a_new_episode():
    s = EscapeSettings(max_time=0.05)
    rule = EscapeRule(s, MARGIN)
    tcp = np.array([0.3, 0.0, 0.4])
    blocking = [Blocking(MARGIN, np.array([-1.0, 0.0, 0.0]))]
    t = 0.0
    for target, seconds in (([0.6, 0.0, 0.4], 6.0), ([0.6, 0.2, 0.4], 1.0)):
        for _ in range(round(seconds / DT)):
            t += DT
            rule.update(t, tcp, np.array(target), blocking)
        if target[1] == 0.0:
            assert rule.count == s.max_attempts  # gave up on this target
    assert rule.count > s.max_attempts  # the target moved 20 cm: worth another try
