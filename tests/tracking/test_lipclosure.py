"""The closed mouth state of p/b/m (facelib.tracking.lipclosure): the detector's thresholds,
the lip FAPs it sets, and the inner-lip aperture on model-made landmarks of the default
head (its MediaPipe-embedded vertices projected like a 640x480 camera)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import default_face
from facelib.errors import ParameterError
from facelib.mpeg4 import N_FAPS, FapStream, fap
from facelib.tracking.embedding import default_head_embedding
from facelib.tracking.faps import measure_faps, mouth_closed
from facelib.tracking.headframe import head_frame
from facelib.tracking.layouts import landmark_layout
from facelib.tracking.lipclosure import (
    bridge_jaw,
    close_lips,
    closed_frames,
    inner_lip_aperture,
    learn_open_gain,
    learn_threshold,
    lip_closure,
    open_lips,
    separation,
)

PIXELS_PER_METRE = 1500.0


def camera(values: np.ndarray) -> np.ndarray:
    """``(n, 478, 3)`` image coordinates of the default head's embedded landmarks."""
    moved = default_face().deform(FapStream(25.0, values))[:, default_head_embedding()]
    return np.asarray(moved, np.float64) * PIXELS_PER_METRE * [1, -1, -1] + [320, 240, 0]


def test_packaged_rule():
    rule = lip_closure()
    assert len(rule.upper) == len(rule.lower) == 5
    assert (np.concatenate([rule.upper, rule.lower]) < 468).all()
    assert 0.0 < rule.close_below <= rule.open_above < 0.2  # MNS0: under 3-4 mm
    assert rule.closed_gap < 0
    # the open lips' gain: one MNS0 of MediaPipe's aperture is 1-4 MNS0 of true separation
    assert 1024 < rule.open_gain < 4096
    assert 0.1 <= rule.jaw_bridge_s <= 0.4     # a p, b or m, not a pause


def test_hysteresis():
    aperture = np.array([0.1, 0.01, 0.03, 0.05, 0.03, 0.01])
    assert closed_frames(aperture, close_below=0.02, open_above=0.04).tolist() == [
        False, True, True, False, False, True]
    assert closed_frames(aperture, close_below=0.02, open_above=0.02).tolist() == [
        False, True, False, False, False, True]


def test_close_lips_lowers_the_separation_only_where_closed():
    rule = lip_closure()
    values = np.zeros((3, N_FAPS))
    values[:, 2] = 200.0                       # open_jaw
    values[2, [3, 4]] = 400.0                  # already pressed
    out = close_lips(values, np.array([False, True, True]), rule)
    separation = rule.jaw_gain * out[:, 2] - out[:, 3] - out[:, 4]
    np.testing.assert_allclose(out[0], values[0])
    np.testing.assert_allclose(separation[1], rule.closed_gap)
    np.testing.assert_allclose(out[2], values[2])
    np.testing.assert_allclose(out[:, 2], 200.0)  # open_jaw is left alone
    assert out[1, 3] == out[1, 4] > 0
    assert out[1, 7] == rule.neighbours[8] * out[1, 3]


def test_bridge_jaw_draws_open_jaw_across_brief_closures_only():
    jaw = np.array([100, 300, 0, 0, 0, 500, 200, 0, 0, 0, 0, 0, 400, 0], np.float64)
    closed = np.zeros(14, bool)
    closed[[0, 2, 3, 4, 7, 8, 9, 10, 11, 13]] = True  # runs: 0 | 2-4 | 7-11 | 13
    out = bridge_jaw(jaw, closed, longest=3)
    np.testing.assert_allclose(out[2:5], [350, 400, 450])   # 300 -> 500 in four steps
    np.testing.assert_allclose(out[7:12], 0.0)              # five frames: too long
    np.testing.assert_allclose(out[[0, 1, 5, 6, 12, 13]], jaw[[0, 1, 5, 6, 12, 13]])
    np.testing.assert_allclose(bridge_jaw(jaw, closed, longest=5)[7:12],
                               [200 + 200 * k / 6 for k in range(1, 6)])
    assert jaw[3] == 0                                       # the input is left alone


def test_open_lips_raises_the_separation_to_the_aperture_in_open_frames_only():
    rule = lip_closure()
    values = np.zeros((4, N_FAPS))
    values[:, 2] = 100.0                       # open_jaw: separation 162 FAP units
    aperture = np.array([0.2, 0.2, 0.01, 0.2])
    closed = np.array([False, True, False, False])
    values[3, [3, 4]] = -400.0                 # already wider open than the aperture asks
    out = open_lips(values, aperture, closed, rule)
    np.testing.assert_allclose(separation(out, rule)[0], rule.open_gain * 0.2)
    np.testing.assert_allclose(out[1:], values[1:])   # closed, narrow, or already open
    np.testing.assert_allclose(out[:, 2], 100.0)      # open_jaw is left alone
    assert out[0, 3] == out[0, 4] < 0
    assert out[0, 7] == rule.neighbours[8] * out[0, 3]


def test_learn_open_gain_is_the_slope_through_zero_of_open_frames():
    aperture = np.array([0.1, 0.2, 0.3, 0.0, 0.05])
    true_separation = np.array([200.0, 400.0, 600.0, -141.0, 900.0])
    is_open = np.array([True, True, True, False, False])
    assert learn_open_gain(aperture, true_separation, is_open) == pytest.approx(2000.0)
    with pytest.raises(ParameterError, match="no open frame"):
        learn_open_gain(aperture, true_separation, np.zeros(5, bool))
    with pytest.raises(ParameterError, match="finite"):
        learn_open_gain(np.array([0.1, np.nan, 0.3, 0.0, 0.05]), true_separation, is_open)
    with pytest.raises(ParameterError, match=r"true_separation \(4,\)"):
        learn_open_gain(aperture, true_separation[:4], is_open)


def test_learn_threshold_is_the_quantile_of_open_frames():
    aperture = np.concatenate([np.zeros(50), np.linspace(0.0, 0.1, 101)])
    is_open = np.arange(151) >= 50
    assert abs(learn_threshold(aperture, is_open, false_closed=0.2) - 0.02) < 1e-12


def test_aperture_tells_pressed_from_open_lips():
    values = np.zeros((6, N_FAPS), np.float32)
    values[4, fap("open_jaw").index] = 300       # jaw open
    for name, value in (("open_jaw", 12), ("lower_t_midlip", 70), ("raise_b_midlip", 90)):
        values[5, fap(name).index] = value       # the p/b/m viseme's press
    frame = head_frame(camera(values), layout=landmark_layout("mediapipe"), span=slice(0, 4))
    aperture = inner_lip_aperture(frame, lip_closure())
    assert aperture[4] > 0.1
    assert aperture[5] < lip_closure().close_below


def test_learn_threshold_refuses_bad_input_with_a_parameter_error():
    aperture = np.linspace(0.0, 0.1, 5)
    with pytest.raises(ParameterError, match="no open frames"):
        learn_threshold(aperture, np.zeros(5, bool))
    with pytest.raises(ParameterError, match=r"aperture \(5,\) and is_open \(4,\)"):
        learn_threshold(aperture, np.ones(4, bool))
    with pytest.raises(ParameterError, match="false_closed"):
        learn_threshold(aperture, np.ones(5, bool), false_closed=1.5)


def test_a_recorded_track_draws_the_jaw_across_a_brief_closure():
    values = np.zeros((24, N_FAPS), np.float32)
    values[8:, fap("open_jaw").index] = 300         # speech: the jaw open throughout
    values[14:17, fap("lower_t_midlip").index] = 350  # an m: the lips press shut over it
    values[14:17, fap("raise_b_midlip").index] = 350
    landmarks = camera(values)
    smooth = measure_faps(landmarks, fps=25.0, neutral=(0, 8)).stream.values[:, 2]
    raw = measure_faps(landmarks, fps=25.0, neutral=(0, 8), smooth=False).stream.values[:, 2]
    frame = head_frame(landmarks, layout=landmark_layout("mediapipe"), span=slice(0, 8))
    closed = mouth_closed(inner_lip_aperture(frame, lip_closure()))
    assert closed[14:17].all() and not closed[[13, 17]].any()
    np.testing.assert_allclose(smooth[14:17], smooth[13] + (smooth[17] - smooth[13])
                               * np.arange(1, 4) / 4, rtol=1e-6)
    assert not np.allclose(raw[14:17], raw[13] + (raw[17] - raw[13]) * np.arange(1, 4) / 4)
