"""The closed loop on a stream no storyboard writes and the model never trained on (issue 37):
FAP groups bumped one at a time (the jaw alone, the outer lip corners apart from the inner
ones, brows raised to 300-320, a blink, a frown; ``closedloop.probe_stream``) with the eyes
looking ahead, on the default and the cartoon head, with the head turning (yaw 25 degrees)
and still, judged as the review proposed (``facelib.tracking.agreement``): a correlation
goal only where a FAP's true spread on the pooled clips is at least 3 times what a still
face turning the same way reads (the wobble, measured on that head), the error in FAP units
elsewhere, each correlation with its 95 % interval over the effective independent samples.

Floors are the figures measured with the packaged model less a margin (printed on failure);
docs/performance-driven.md has the table and says which of the issue's goals are met.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mediapipe")
pytestmark = [pytest.mark.render, pytest.mark.slow]

import facelib  # noqa: E402
from facelib.mpeg4 import ANGLE_UNIT  # noqa: E402
from facelib.tracking.agreement import agreement  # noqa: E402
from facelib.tracking.closedloop import (  # noqa: E402
    closed_loop,
    closure_events,
    event_recall,
    probe_stream,
    still_face,
)

JUDGED = (3, 12, 13, 59, 60, 53, 54, 31, 32, 35, 36, 19, 20, 48, 49, 50)
"""The FAP groups of the issue's goal: jaw, lip corners (inner and outer raise, outer
stretch), brows, upper lids, head."""
HEADS = ("default", "cartoon")


def _face(which: str):
    if which == "default":
        return None
    return facelib.setup_face("examples/heads/cartoon_head.obj",
                              landmarks="examples/heads/cartoon_landmarks.json")


@pytest.fixture(scope="module", params=HEADS)
def head(request):
    """One head's pooled clips (the probe with head turns and with the head still) and its
    still face turning as the probe does."""
    face = _face(request.param)
    loops = [closed_loop(probe_stream(turns=turns), face=face) for turns in (True, False)]
    still = closed_loop(still_face(probe_stream(turns=True)), face=face)
    wobble = still.tracked.stream.values.astype(np.float64).std(axis=0)
    found = agreement([loop.truth.values for loop in loops],
                      [loop.tracked.stream.values for loop in loops], wobble, JUDGED)
    return request.param, loops, {a.fap: a for a in found}


CORRELATION_FLOORS = {
    "default": {3: 0.9, 12: 0.85, 13: 0.85, 59: 0.6, 60: 0.6, 31: 0.9, 32: 0.9, 19: 0.85,
                20: 0.85, 48: 0.95, 49: 0.98, 50: 0.95},
    "cartoon": {3: 0.8, 12: 0.6, 13: 0.6, 59: 0.4, 60: 0.4, 31: 0.85, 32: 0.85, 19: 0.8,
                20: 0.65, 48: 0.85, 49: 0.98, 50: 0.95},
}
"""Correlation floors where the spread rule applies (every judged FAP here: the probe moves
each far above the wobble)."""
GAIN_RANGE = {
    "default": {3: (0.8, 1.25), 31: (0.7, 1.25), 32: (0.7, 1.25), 49: (0.9, 1.1)},
    "cartoon": {3: (0.8, 1.4), 31: (0.6, 1.25), 32: (0.6, 1.25), 49: (0.95, 1.1)},
}


def test_spread_rule_and_intervals(head):
    name, _, found = head
    for fap_id, floor in CORRELATION_FLOORS[name].items():
        a = found[fap_id]
        assert a.judged == "correlation", (fap_id, a)
        assert a.low <= a.correlation <= a.high
        assert 10 < a.samples < 600, a
        assert a.correlation > floor, (name, fap_id, a)
    for fap_id, (low, high) in GAIN_RANGE[name].items():
        assert low < found[fap_id].gain < high, (name, fap_id, found[fap_id])


def test_no_false_gaze(head):
    """The eyes look ahead all through the probe: what tracking reads as a look is the
    jaw's, the brows' and the lids' motion leaking into the gaze."""
    name, loops, _ = head
    worst = []
    for loop in loops:
        truth, values = loop.truth.values, loop.tracked.stream.values
        open_ = truth[:, 18] < 300  # blinks hide the iris
        degrees = np.degrees(values[open_][:, 22:26].astype(np.float64) * ANGLE_UNIT)
        worst.append(float(np.abs(degrees).max()))
    assert max(worst) < GAZE_BOUND[name], (name, worst)


GAZE_BOUND = {"default": 8.0, "cartoon": 12.0}


def test_blinks_found(head):
    _, loops, _ = head
    for loop in loops:
        for fap_id in (19, 20):
            events = closure_events(loop.truth.values[:, fap_id - 1], 600)
            assert event_recall(events, loop.tracked.stream.values[:, fap_id - 1]) == 1.0
