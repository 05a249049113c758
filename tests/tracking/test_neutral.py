"""The neutral frames found when the user names none (facelib.tracking.neutral): a track
whose first frame holds the jaw open is warned about and measured from its real neutral;
tracks that start neutral keep their first frame."""

from __future__ import annotations

import importlib.util
import warnings

import numpy as np
import pytest

from facelib.errors import TrackingWarning
from facelib.mpeg4.stream import FapStream
from facelib.tracking.neutral import neutral_rule, neutral_scores, neutral_window

FPS = 25


def _first_pass(n: int, *, held_jaw: float, pressed: slice | None = None) -> np.ndarray:
    """``(n, 84)`` what a first pass reads when the first 15 frames hold the jaw at
    ``held_jaw`` and frames 15-24 are the neutral: the jaw read from frame 0 (a talk after
    frame 25), the corners likewise; ``pressed`` frames read a lip press."""
    rng = np.random.default_rng(3)
    values = rng.normal(0.0, 4.0, (n, 84))
    jaw = np.zeros(n)
    jaw[25:] = 150 * (1 - np.cos(2 * np.pi * 2.5 * np.arange(n - 25) / FPS))
    jaw[:15] = held_jaw
    values[:, 2] += jaw - held_jaw
    values[15:, [11, 12]] -= 0.5 * held_jaw
    if pressed is not None:
        values[pressed, 2] -= 100
    return values


def test_a_first_frame_with_the_jaw_open_is_not_the_neutral():
    choice = neutral_window(_first_pass(100, held_jaw=200), fps=FPS)
    assert choice.searched and choice.jaw_below > 150
    assert choice.span.start >= 15 and choice.span.stop <= 25
    assert choice.span.stop - choice.span.start == round(neutral_rule().window_s * FPS)


def test_brief_presses_and_a_neutral_start_keep_the_first_frame():
    values = _first_pass(100, held_jaw=0, pressed=slice(40, 48))
    choice = neutral_window(values, fps=FPS)
    assert not choice.searched and choice.span == slice(0, 1)
    assert neutral_window(values, fps=FPS, first=7).span == slice(7, 8)


def test_excluded_frames_are_never_the_neutral():
    values = _first_pass(100, held_jaw=200)
    found = neutral_window(values, fps=FPS).span
    excluded = range(found.start, found.stop)
    again = neutral_window(values, fps=FPS, excluded=excluded).span
    assert not set(range(again.start, again.stop)) & set(excluded)


def test_scores_are_zero_for_a_still_neutral_and_inf_where_the_jaw_is_open():
    values = np.zeros((30, 84))
    values[10:20, 2] = 300
    score = neutral_scores(values)
    assert np.all(score[:10] == 0) and np.all(np.isinf(score[10:20]))


@pytest.mark.render
@pytest.mark.slow
def test_a_rendered_track_is_measured_from_its_real_neutral():
    """Closed loop: the default head holds jaw 200 and corners 210 for 0.6 s, rests 0.4 s,
    then talks; tracked with no neutral given, it warns and reads what the true neutral
    (frames 15-24) reads, not what the first frame does."""
    if importlib.util.find_spec("mediapipe") is None:
        pytest.skip("needs the tracking extra")
    from facelib.tracking.closedloop import closed_loop
    from facelib.tracking.faps import find_neutral, measure_faps

    values = np.zeros((100, 84), np.float32)
    values[:15, 2], values[:15, 11], values[:15, 12] = 200, 210, 210
    t = np.arange(75) / FPS
    values[25:, 2] = 150 * (1 - np.cos(2 * np.pi * 2.5 * t))
    values[25:, 11] = values[25:, 12] = 80 * np.sin(2 * np.pi * 0.7 * t)
    points = closed_loop(FapStream(FPS, values), neutral_frames=0, brow_image=False).landmarks
    found = find_neutral(points, fps=FPS)
    # frames 15-24 rest, and the talk starts from jaw 0 at frame 25
    assert found.searched and found.span.start >= 15 and found.span.stop <= 27
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        auto = measure_faps(points, fps=FPS).stream.values
    assert any(isinstance(w.message, TrackingWarning) and "not a neutral face" in
               str(w.message) for w in caught)
    true = measure_faps(points, fps=FPS, neutral=(15, 25)).stream.values
    first = measure_faps(points, fps=FPS, neutral=0).stream.values
    # measured from the held frame, every frame is off by most of what the tracker reads of
    # the hold (its reading of jaw 200 and corners 210 varies from run to run, 100-130)
    for fap in (3, 12, 13):
        auto_error = np.abs(auto[:, fap - 1] - true[:, fap - 1]).max()
        first_error = np.abs(first[:, fap - 1] - true[:, fap - 1]).max()
        assert auto_error < 20
        assert first_error > max(0.75 * true[:15, fap - 1].mean(), 4 * auto_error)
