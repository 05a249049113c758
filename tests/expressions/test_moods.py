"""Moods (issue 32, item 3): a baseline under the explicit expressions, data-driven scales."""

from __future__ import annotations

import numpy as np
import pytest

from facelib import FdlError, fap, fdl
from facelib.animation import animate
from facelib.cues import ExpressionCue, MoodCue, Storyboard
from facelib.expressions import animate as expression_track
from facelib.expressions import default_library, mood_curves, moods
from facelib.fdl.sandbox import Sandbox
from facelib.mpeg4.track import FapTrack
from facelib.sync.nods import Nods, add_brow_beats

CORNER = fap("raise_l_cornerlip").index
BROW = fap("raise_l_i_eyebrow").index
PITCH = fap("head_pitch").index


def test_the_issue_moods_are_data_with_their_columns():
    table = moods()
    assert {"neutral", "happy", "sad", "angry", "fear", "disgust", "love", "sleepy"} <= set(table)
    assert table["neutral"].expression == "" and table["neutral"].head_motion_scale == 1.0
    assert table["sleepy"].head_motion_scale < 1 < table["fear"].head_motion_scale
    for mood in table.values():
        assert mood.expression == "" or mood.expression in default_library()
        assert mood.blink_rate_scale > 0 and mood.idle_amplitude > 0


def test_a_mood_holds_its_expression_after_easing_in():
    curves = mood_curves([MoodCue("happy", 0, intensity=1.0, ease_ms=400)], fps=25,
                         n_frames=50)
    joy = default_library().get("joy")
    held = joy.share(moods()["happy"].level) * joy.values[CORNER]
    assert curves.values[5, CORNER] == pytest.approx(0.5 * held)  # half way through the ease
    assert curves.values[20, CORNER] == pytest.approx(held)
    assert curves.scales["head_motion_scale"][20] == pytest.approx(1.2)
    assert curves.scales["speech_brow"][20] == pytest.approx(35)


def test_moods_crossfade_and_intensity_scales_them():
    cues = [MoodCue("happy", 0, ease_ms=0), MoodCue("sad", 1000, intensity=0.5, ease_ms=1000)]
    curves = mood_curves(cues, fps=50, n_frames=200)  # frame 75 = 1.5 s, half way
    scale = curves.scales["head_motion_scale"]
    assert scale[10] == pytest.approx(1.2)
    assert scale[75] == pytest.approx(0.5 * 1.2 + 0.5 * (1 + 0.5 * (0.6 - 1)))  # mid fade
    assert scale[199] == pytest.approx(1 + 0.5 * (0.6 - 1))
    assert np.abs(np.diff(curves.values[:, CORNER])).max() < 40  # no jump in the fade
    sadness = default_library().get("sadness")
    assert curves.values[199, CORNER] == pytest.approx(
        sadness.share(0.5 * moods()["sad"].level) * sadness.values[CORNER], rel=1e-5)


def test_an_explicit_expression_covers_the_mood_and_hands_back():
    curves = mood_curves([MoodCue("happy", 0, ease_ms=0)], fps=25, n_frames=100)
    cue = ExpressionCue("surprise", 1000, 2000, ramp_in_ms=400, ramp_out_ms=400)
    track = expression_track([cue], fps=25, n_frames=100, moods=curves)
    surprise = default_library().get("surprise")
    brow = surprise.values[BROW]
    assert track.values[50, BROW] == pytest.approx(brow, rel=1e-5)  # surprise's own brows
    assert track.values[50, CORNER] == pytest.approx(curves.values[50, CORNER])  # mood kept
    assert track.values[10, CORNER] == pytest.approx(curves.values[10, CORNER])
    assert track.values[90, CORNER] == pytest.approx(curves.values[90, CORNER])  # after it
    jaw = fap("open_jaw").index
    assert track.values[30, jaw] == pytest.approx(0.5 * surprise.values[jaw], rel=1e-4)
    assert track.weight[10, CORNER] == 1 and track.weight[10, jaw] == 0


def _board(*cues: MoodCue) -> Storyboard:
    return Storyboard(seed=5, moods=cues,
                      expressions=(ExpressionCue("joy", 0, 8000, intensity=0.0),))


def test_moods_scale_head_motion_and_are_deterministic():
    calm = animate(_board(MoodCue("sleepy", 0, ease_ms=0))).faps.values
    plain = animate(_board()).faps.values
    again = animate(_board(MoodCue("sleepy", 0, ease_ms=0))).faps.values
    assert np.array_equal(calm, again)
    sleepy_pitch = fap("head_pitch").index
    # the sleepy expression sinks the head; its drift around that is 0.45 times the plain one
    drift = calm[:, sleepy_pitch] - calm[:, sleepy_pitch].mean()
    ratio = drift.std() / plain[:, sleepy_pitch].std()
    assert ratio == pytest.approx(moods()["sleepy"].head_motion_scale, rel=0.1)


def test_brow_beats_follow_the_accents_and_the_mood():
    n = 40
    track = FapTrack.empty(n, fps=25)
    strength = np.zeros(n)
    strength[20] = 1.0
    up = add_brow_beats(track, strength=strength, nods=Nods(), brow=np.full(n, 30.0))
    down = add_brow_beats(track, strength=strength, nods=Nods(), brow=np.full(n, -20.0))
    assert up.values[20, BROW] == pytest.approx(30) and down.values[20, BROW] == pytest.approx(-20)
    assert up.values[5, BROW] == 0 and up.weight[20, BROW] == 1
    same = add_brow_beats(track, strength=strength, nods=Nods(), brow=np.zeros(n))
    assert same is track


def test_storyboard_mood_calls():
    board = fdl.loads('mood { "happy", intensity = 0.6 }\n'
                      'mood { "Sad", at = 3, ease = "500ms" }\nmood { "love" }\n',
                      sandbox=Sandbox())
    assert [(m.name, m.start_ms, m.intensity, m.ease_ms) for m in board.moods] == [
        ("happy", 0, 0.6, None), ("sad", 3000, 1.0, 500), ("love", 5000, 1.0, None)]
    assert board.moods[1].origin[1] == 2


@pytest.mark.parametrize(("text", "message"), [
    ('mood { "hapy", at = 1 }', r"<string>:1:.*'hapy'.*did you mean 'happy'"),
    ('\nmood { "happy", intensity = 2 }', r":2:.*intensity must be a number from 0 to 1"),
    ('mood { "happy", dur = 2 }', r"unknown field 'dur'"),
    ('mood { at = 2 }', r"one mood name first"),
    ('mood { "sad", at = 1 }\nmood { "fear", at = 1 }', r":2:.*both start at 1000 ms"),
])
def test_bad_mood_calls_name_the_line(text, message):
    with pytest.raises(FdlError, match=message):
        fdl.loads(text, sandbox=Sandbox())
