"""``animate``: the speech generator's FapTrack, timeline and speaking mask."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib.cues import SpeechSpec, VisemeCue
from facelib.errors import SpeechError
from facelib.mpeg4.tables import fap
from facelib.visemes import animate, driven_faps, viseme_targets

FIXTURES = Path(__file__).parents[1] / "data" / "speech" / "alignment"


def test_text_only_track_shape_weights_and_offset():
    anim = animate(SpeechSpec(text="Bob saw a blue moon.", start_ms=1000), fps=25)
    track = anim.track
    assert track.fps == 25 and track.values.shape == (track.n_frames, 84)
    assert track.n_frames == len(anim.speaking)
    assert not track.weight[:, ~driven_faps()].any()
    assert not track.weight[: int(0.8 * 25)].any()  # nothing before the speech starts
    assert track.weight[:, fap("open_jaw").index].max() == 1
    assert anim.timeline[0].start_ms == 1000 and anim.speech.source == "synthesis"
    assert anim.speaking.any() and not anim.speaking[:25].any()
    assert not anim.speaking.flags.writeable
    # the first bilabial is closed at its frames
    pp = next(v for v in anim.timeline if v.name == "PP")
    k = int(np.ceil(pp.start_ms * 25 / 1000))
    upper = fap("lower_t_midlip").index
    assert track.values[k, upper] == pytest.approx(viseme_targets()[1, upper])


def test_deterministic():
    spec = SpeechSpec(text="Hello there, how are you?")
    a, b = animate(spec, fps=30), animate(spec, fps=30)
    np.testing.assert_array_equal(a.track.values, b.track.values)
    np.testing.assert_array_equal(a.track.weight, b.track.weight)


def test_stored_viseme_script_used_directly():
    cues = (VisemeCue("silence", 0, 440), VisemeCue("A", 440, 240), VisemeCue("kg", 680, 40),
            VisemeCue("Q", 720, 40), VisemeCue("silence", 760, 1080))
    anim = animate(SpeechSpec(visemes=cues), fps=25)
    assert [v.name for v in anim.timeline][:3] == ["sil", "aa", "kk"]
    assert anim.speech.source == "script" and anim.track.n_frames == 47
    jaw = anim.track.values[:, fap("open_jaw").index]
    assert jaw[int(0.56 * 25)] == pytest.approx(viseme_targets()[10, fap("open_jaw").index],
                                                rel=0.05)
    assert anim.speaking[int(0.5 * 25)] and not anim.speaking[int(1.5 * 25)]


def test_audio_and_text_uses_alignment():
    pytest.importorskip("pocketsphinx")
    spec = SpeechSpec(audio=FIXTURES / "quick_fox.flac",
                      text="The quick brown fox jumps over the lazy dog.", start_ms=500)
    anim = animate(spec, fps=25)
    assert anim.speech.source == "forced"
    assert anim.track.n_frames == int((500 + anim.speech.duration_ms) * 25 / 1000) + 1
    first = next(v for v in anim.timeline if not v.is_silence)
    assert abs(first.start_ms - (500 + 165)) <= 40


def test_nothing_to_say():
    with pytest.raises(SpeechError, match=r"story\.fdl:7"):
        animate(SpeechSpec(origin=("story.fdl", 7)), fps=25)


def test_numpy_frame_rates_are_accepted_as_fapstream_accepts_them():
    spec = SpeechSpec(text="Hello there.")
    plain = animate(spec, fps=25)
    numpy_rate = animate(spec, fps=np.float32(25))  # used to raise ParameterError
    assert numpy_rate.track.fps == 25.0
    assert np.array_equal(plain.track.values, numpy_rate.track.values)
