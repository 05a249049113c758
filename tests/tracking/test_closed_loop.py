"""The closed loop: the default head rendered from a known stream (speech, expressions,
gaze, blinks, head turns up to 20 degrees), tracked with MediaPipe, compared curve by curve.

The thresholds are the figures this implementation reaches (benchmarks/tracking.py prints
them all) minus a margin: they guard against regressions. They are below the issue's goal
of 0.9 for the face FAPs; docs/performance-driven.md says where and why.
"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mediapipe")
pytestmark = [pytest.mark.render, pytest.mark.slow]

import facelib  # noqa: E402
from facelib.tracking.closedloop import (  # noqa: E402
    closed_loop,
    closure_events,
    event_recall,
    with_head_turns,
)


@pytest.fixture(scope="module")
def loop():
    hello = facelib.run_fdl("examples/hello/hello.fdl").faps
    return closed_loop(with_head_turns(hello, frames=110))


def test_head_pose_comes_back(loop):
    assert loop.correlation(49) > 0.95   # yaw, up to 20 degrees
    assert loop.correlation(48) > 0.85   # pitch
    assert loop.correlation(50) > 0.85   # roll
    assert 0.8 < loop.gain(49) < 1.25


def test_face_faps_follow_the_truth(loop):
    # the lip corners' sideways FAPs 53/54 no longer move in hello (joy lifts the corners
    # through the learned fields of issue 14), so they are not compared here
    floors = {3: 0.65, 19: 0.5, 20: 0.6, 24: 0.6}
    found = {fap_id: round(loop.correlation(fap_id), 3) for fap_id in floors}
    assert all(found[k] > v for k, v in floors.items()), found


def test_blinks_come_back(loop):
    for fap_id in (19, 20):
        events = closure_events(loop.truth.values[:, fap_id - 1], 600)
        assert events
        assert event_recall(events, loop.tracked.stream.values[:, fap_id - 1]) >= 0.9


def test_no_frame_lost_and_fapu_plausible(loop):
    assert loop.tracked.filled_frames == ()
    assert np.isfinite(loop.landmarks).all()
    assert 60 < loop.tracked.fapu["ES"] * 1024 < 120   # pixels between the pupils


def test_packaged_embedding_matches_a_fresh_one() -> None:
    """The default head's landmark embedding (package data) is what embed_landmarks finds
    now: the data was regenerated with the head, for at least 95 % of the landmarks the same
    vertex, the rest within 3 mm."""
    from facelib.engine import default_face
    from facelib.tracking.embedding import default_head_embedding, embed_landmarks

    face = default_face()
    fresh, packaged = embed_landmarks(face), default_head_embedding()
    assert (fresh == packaged).mean() >= 0.95
    gap = np.linalg.norm(face.vertices[fresh] - face.vertices[packaged], axis=1)
    assert gap.max() < 0.003
