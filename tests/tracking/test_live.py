"""Live tracking, frame by frame: the offline path's numbers, causally; a video read as a
camera."""

from __future__ import annotations

import numpy as np
import pytest
from test_observation import camera

from facelib.errors import ParameterError, TrackingError
from facelib.mpeg4 import ANGLE_UNIT
from facelib.tracking.faps import measure_faps
from facelib.tracking.live import LiveFaps

NEUTRAL = 4


def smooth_stream(n: int) -> np.ndarray:
    """``(n, 84)`` a slow jaw, smile and head turn, neutral first: what a filter keeps."""
    values = np.zeros((n, 84), np.float32)
    t = np.arange(n - NEUTRAL) / 25.0
    values[NEUTRAL:, 2] = 300 * (1 - np.cos(2 * np.pi * 0.7 * t))  # open_jaw
    values[NEUTRAL:, 11] = values[NEUTRAL:, 12] = 200 * np.sin(2 * np.pi * 0.3 * t)  # corners
    values[NEUTRAL:, 48] = np.radians(12) * np.sin(2 * np.pi * 0.2 * t) / ANGLE_UNIT  # yaw
    return values


def run(live: LiveFaps, landmarks: np.ndarray) -> np.ndarray:
    """``(n, 84)`` what ``live`` gives frame by frame (NaN for None)."""
    rows = [live.push(frame) for frame in landmarks]
    return np.stack([np.full(84, np.nan) if r is None else r for r in rows])


def test_unsmoothed_live_faps_are_the_offline_ones():
    landmarks = camera(smooth_stream(60))
    live = run(LiveFaps(fps=25, neutral_frames=NEUTRAL, smooth=False), landmarks)
    offline = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL), smooth=False).stream
    assert np.isnan(live[:NEUTRAL]).all()
    np.testing.assert_allclose(live[NEUTRAL:], offline.values[NEUTRAL:], atol=1e-9)


def test_live_smoothing_is_causal_and_close_to_the_recorded_one():
    values = smooth_stream(150)
    landmarks = camera(values)
    live = run(LiveFaps(fps=25, neutral_frames=NEUTRAL), landmarks)[NEUTRAL:]
    offline = measure_faps(landmarks, fps=25, neutral=(0, NEUTRAL)).stream.values[NEUTRAL:]
    for col in (2, 11, 48):  # open_jaw, a lip corner, head yaw
        assert np.corrcoef(live[:, col], offline[:, col])[0, 1] > 0.97, col
    # a future frame changes no past frame
    cut = run(LiveFaps(fps=25, neutral_frames=NEUTRAL), landmarks[:100])[NEUTRAL:]
    np.testing.assert_array_equal(cut, live[:100 - NEUTRAL])


def test_a_lost_face_holds_the_last_faps():
    landmarks = camera(smooth_stream(20))
    landmarks[12:15] = np.nan
    live = LiveFaps(fps=25, neutral_frames=NEUTRAL)
    out = run(live, landmarks)
    for i in (12, 13, 14):
        np.testing.assert_array_equal(out[i], out[11])
    assert live.push(None) is not None and live.neutral is not None
    assert live.mask is not None and live.mask[2]  # open_jaw is measured


def test_the_neutral_waits_for_faces():
    live = LiveFaps(fps=25, neutral_frames=2)
    landmarks = camera(smooth_stream(6))
    assert live.push(None) is None and live.push(landmarks[0]) is None
    with pytest.raises(TrackingError, match=r"shape \(68, 3\) after ones of \(478, 3\)"):
        live.push(landmarks[1, :68])
    assert live.push(landmarks[1]) is None and live.neutral is not None
    assert live.push(landmarks[2]) is not None
    with pytest.raises(TrackingError, match="shape"):
        live.push(landmarks[3, :68])


def test_bad_options_are_named():
    with pytest.raises(ParameterError, match="neutral_frames"):
        LiveFaps(fps=25, neutral_frames=0)
    live = LiveFaps(fps=25, neutral_frames=1, rig="observed")
    flat = camera(smooth_stream(2))[1, :, :2]
    with pytest.raises(ParameterError, match="observation model"):
        live.push(flat)


def test_the_filter_follows_the_frames_real_intervals():
    landmarks = camera(smooth_stream(60))
    nominal = run(LiveFaps(fps=25, neutral_frames=NEUTRAL), landmarks)
    live = LiveFaps(fps=25, neutral_frames=NEUTRAL)
    same = np.stack([np.full(84, np.nan) if r is None else r
                     for r in (live.push(f, dt=0.04) for f in landmarks)])
    np.testing.assert_array_equal(same, nominal)
    live = LiveFaps(fps=25, neutral_frames=NEUTRAL)  # a camera that delivers 5 frames/s
    slow = np.stack([np.full(84, np.nan) if r is None else r
                     for r in (live.push(f, dt=0.2) for f in landmarks)])
    unfiltered = run(LiveFaps(fps=25, neutral_frames=NEUTRAL, smooth=False), landmarks)
    # frames far apart are filtered less: closer to the unfiltered jaw
    lag = np.abs(nominal[NEUTRAL:, 2] - unfiltered[NEUTRAL:, 2]).mean()
    assert np.abs(slow[NEUTRAL:, 2] - unfiltered[NEUTRAL:, 2]).mean() < 0.5 * lag
