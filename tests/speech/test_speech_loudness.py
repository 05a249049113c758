"""Per-phone loudness (dBFS) for the viseme track."""

import numpy as np
import pytest

from facelib.cues import SpeechSpec
from facelib.speech.loudness import FLOOR_DB, phone_loudness
from facelib.speech.timeline import Span
from facelib.visemes import animate


def test_sine_levels_and_silence():
    rate = 16000
    t = np.arange(rate) / rate
    x = np.concatenate([0.5 * np.sin(2 * np.pi * 220 * t), np.zeros(rate)])
    spans = [Span("a", 0, 1000), Span("SIL", 1000, 2000), Span("b", 2000, 2100)]
    level = phone_loudness(x, sample_rate=rate, spans=spans)
    assert level[0] == pytest.approx(20 * np.log10(0.5 / np.sqrt(2)), abs=0.01)
    assert level[1] == FLOOR_DB and level[2] == FLOOR_DB  # silence; past the end


@pytest.mark.speech
def test_viseme_track_carries_loudness_of_the_synthesized_speech():
    anim = animate(SpeechSpec(text="Bob bought a big map.", start_ms=400), fps=25)
    assert anim.loudness.shape == (anim.track.n_frames,)
    assert np.all(anim.loudness[:10] == FLOOR_DB)  # before the speech starts
    assert anim.loudness[anim.speaking].mean() > -40
