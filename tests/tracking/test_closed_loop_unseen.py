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
    wobble = (still.tracked.stream.values.astype(np.float64)
              - still.truth.values).std(axis=0)
    found = agreement([loop.truth.values for loop in loops],
                      [loop.tracked.stream.values for loop in loops], wobble, JUDGED)
    return request.param, loops, {a.fap: a for a in found}


FLOORS = {
    "default": {3: (0.93, 60), 12: (0.78, 60), 13: (0.78, 60), 59: (0.1, 70), 60: (0.1, 70),
                53: (0.6, 30), 54: (0.6, 30), 31: (0.95, 25), 32: (0.95, 25), 35: (0.92, 25),
                36: (0.92, 25), 19: (0.93, 70), 20: (0.93, 70), 48: (0.98, 1000),
                49: (0.99, 1200), 50: (0.98, 500)},
    "cartoon": {3: (0.7, 120), 12: (0.3, 190), 13: (0.3, 190), 59: (0.05, 75), 60: (0.05, 75),
                53: (0.4, 35), 54: (0.4, 35), 31: (0.9, 30), 32: (0.9, 30), 35: (0.85, 35),
                36: (0.85, 35), 19: (0.9, 90), 20: (0.9, 90), 48: (0.85, 4500),
                49: (0.99, 2000), 50: (0.97, 1000)},
}
"""Per FAP: the correlation floor where the spread rule asks for a correlation, the bound on
the root-mean-square error (FAP units) where it does not. Measured with the packaged model
on the cached renders (docs/performance-driven.md, "The probe stream"): on the default head
open_jaw 0.97, corners 12/13 0.87/0.84, outer corners 59/60 0.33/0.29 (the issue's goal of
0.9 is not met: MediaPipe's corner landmarks move alike for the inner and the outer raise),
outer stretch 53/54 0.77/0.72, brows 0.97-0.99, upper lids 0.97, head 0.997-0.999; on the
cartoon head the wobble is larger (open_jaw 78, corners 126-180 units) and the rule asks for
the error there."""
GAIN_RANGE = {
    "default": {3: (0.75, 1.25), 31: (0.9, 1.25), 32: (0.9, 1.25), 19: (0.8, 1.25),
                49: (0.95, 1.05)},
    "cartoon": {3: (0.75, 1.25), 31: (0.8, 1.25), 32: (0.8, 1.25), 49: (0.95, 1.1)},
}
"""Gains measured: open_jaw 0.82 and 0.95, brows 1.06/1.08 and 0.93/0.97 (0.54-0.60 with the
model before issue 37, capped by its training range), head yaw 0.99 and 1.05 (issue 37's
goal: within 5 %)."""


def test_spread_rule_and_intervals(head):
    name, _, found = head
    for fap_id, (floor, bound) in FLOORS[name].items():
        a = found[fap_id]
        assert a.low <= a.correlation <= a.high
        assert 10 < a.samples < 600, a
        if a.judged == "correlation":
            assert a.correlation > floor, (name, fap_id, a)
        else:
            assert a.error < bound, (name, fap_id, a)
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


GAZE_BOUND = {"default": 11.0, "cartoon": 14.0}
"""Largest false look measured outside blinks: 9.2 and 11.6 degrees (with head turns; 15.5
and 16.5 with the model before issue 37). The issue's goal of 2 degrees is not met."""


def test_blinks_found(head):
    _, loops, _ = head
    for loop in loops:
        for fap_id in (19, 20):
            events = closure_events(loop.truth.values[:, fap_id - 1], 600)
            assert event_recall(events, loop.tracked.stream.values[:, fap_id - 1]) == 1.0
