"""Blinks and head-eye coordination by the measured norms (issue 32 item 5): blink rates by
state from alive/blinks.json, never closer than the least interval, gaze-evoked blinks on
large shifts, and the head's share of a gaze shift so the eyes stay near the head's
straight-ahead. All measured on generated streams (seeded), never on a clock."""

from __future__ import annotations

import numpy as np
import pytest

from facelib import animate, fap
from facelib.errors import FdlError, ParameterError
from facelib.fdl import loads
from facelib.gaze import simulate
from facelib.gaze.norms import BLINK_STATES, blink_norms, head_eye_rule

DEG = np.pi / 180 / 1e-5
STATES = {"rest": (("default", "thinking"), False), "listening": (("default", "listening"), False),
          "talking": (("default", "talking"), True), "reading": (("concentration",), False)}
CITED = {"rest": (4.0, 30.0), "listening": (4.0, 30.0), "talking": (10.0, 42.0),
         "reading": (0.5, 9.0)}
"""Bentivoglio et al. 1997's mean +- one between-subject sd (17 +- 13, 26 +- 16, 4.5 +- 4)."""


def test_every_state_has_a_cited_rate():
    norms = blink_norms()
    assert set(norms.per_min) == set(BLINK_STATES)
    assert (norms.rate("rest"), norms.rate("talking"), norms.rate("reading")) == (17, 26, 4.5)
    assert norms.min_interval_s == pytest.approx(1.0)


@pytest.mark.parametrize("state", list(STATES))
def test_blink_rate_by_state_and_least_interval(state):
    args, speaking = STATES[state]
    anim = simulate(*args, seconds=600, seed=11, speaking=speaking)
    per_min = len(anim.blinks) / 10
    assert per_min == pytest.approx(blink_norms().rate(state), rel=0.15)
    low, high = CITED[state]
    assert low <= per_min <= high
    gaps = np.diff([b.start for b in anim.blinks])
    assert gaps.min() >= blink_norms().min_interval_s - 1e-9


def test_least_interval_holds_at_twice_the_rate():
    anim = simulate("default", "talking", seconds=600, seed=2, speaking=True, blink_rate=2.0)
    gaps = np.diff([b.start for b in anim.blinks])
    assert gaps.min() >= blink_norms().min_interval_s - 1e-9
    base = simulate("default", "talking", seconds=600, seed=2, speaking=True)
    assert len(anim.blinks) > 1.6 * len(base.blinks)  # 52/min asked, near the 1 s floor


def test_evoked_blinks_start_with_large_shifts_and_keep_the_rate():
    anim = simulate("default", "talking", seconds=600, seed=5, speaking=True)
    onsets = {round(s.start, 9): s.magnitude for s in anim.saccades}
    evoked = [b for b in anim.blinks if b.evoked]
    assert len(evoked) > 10
    assert all(onsets[round(b.start, 9)] >= blink_norms().evoked_threshold_deg for b in evoked)
    assert len(anim.blinks) / 10 == pytest.approx(26.0, rel=0.15)  # evoked ones replace
    assert blink_norms().evoked_probability(40.0) == 1.0
    assert blink_norms().evoked_probability(10.0) == 0.0


def test_a_behaviour_may_name_its_blink_state():
    sb = loads('define_gaze { "reader", base = "default", blink_state = "reading" }\n'
               'look { "reader", dur = 600 }')
    anim = animate(sb)
    assert len([e for e in anim.gaze_events if type(e).__name__ == "Blink"]) / 10 < 7
    with pytest.raises(FdlError, match="blink_state"):
        animate(loads('define_gaze { "x", base = "default", blink_state = "sleeping" }\n'
                      'look { "x", dur = 1 }'))
    with pytest.raises(ParameterError, match="blink_rate"):
        simulate("default", seconds=1, blink_rate=-1.0)


def test_head_eye_rule_keeps_the_eyes_near_the_head():
    rule = head_eye_rule()
    for size in (5.0, 10.0, 15.0, 18.0, 30.0, 60.0, 90.0):
        head = rule.head_for(np.array([size, 0.0]))
        assert 0.0 <= head[0] <= size and head[1] == 0.0
        assert size - head[0] <= rule.eye_rest_max_deg + 1e-9
    assert rule.head_for(np.array([8.0, 0.0]))[0] == 0.0  # small shifts: the eyes alone
    assert rule.head_for(np.array([18.0, 0.0]))[0] >= 3.0


@pytest.mark.parametrize("seed", range(4))
def test_an_18_deg_look_turns_the_head_and_keeps_the_eyes_within_22_deg(seed):
    sb = loads(f'fps = 25\nseed = {seed}\nlook {{ "lookTo", "left", 18.0, at = 1.0, dur = 3 }}')
    anim = animate(sb)
    hold = slice(50, 100)
    planned = anim.tracks["gaze"].values[hold, fap("head_yaw").index] / DEG
    assert planned.min() >= 3.0
    values = anim.faps.values[hold] / DEG
    eyes = values[:, [fap("yaw_l_eyeball").index, fap("yaw_r_eyeball").index]]
    assert np.abs(eyes).max() <= 22.0
    assert values[:, fap("head_yaw").index].mean() >= 2.0  # with the listener's drift
    gaze_line = values[:, fap("head_yaw").index] + eyes[:, 0]
    assert np.abs(gaze_line - 18.0).max() < 1.0  # the eyes counter-roll the idle motion


def test_a_40_deg_look_leaves_the_eyes_within_the_rest_range():
    anim = simulate("lookTo", "right", 40.0, seconds=3.0, seed=0)
    assert abs(anim.eyes[-1, 0]) <= head_eye_rule().eye_rest_max_deg + 0.5
    assert anim.head[-1, 0] == pytest.approx(-(40.0 - head_eye_rule().eye_rest_max_deg))
