"""Louder speech opens the jaw further (issue 14, item 8)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib.cues import SpeechSpec
from facelib.mpeg4.tables import fap
from facelib.visemes import animate
from facelib.visemes.loudness import jaw_gain
from facelib.visemes.tables import loudness_rules

HELLO = Path(__file__).parent.parent.parent / "examples" / "hello"
JAW = fap("open_jaw").index


def test_gain_follows_the_level_within_bounds():
    rules = loudness_rules()
    levels = np.array([-100.0, -13.0, -23.0, -39.0])
    gain = jaw_gain(levels, rules=rules)
    assert gain[0] == 1.0  # silence
    assert 1.2 < gain[1] <= rules["max_gain"]
    assert gain[2] == pytest.approx(1.0)
    assert gain[3] == pytest.approx(max(rules["min_gain"], 1 - 16 * rules["per_db"]))


def test_loud_and_quiet_readings_open_the_jaw_differently(tmp_path):
    import soundfile

    samples, rate = soundfile.read(str(HELLO / "hello.flac"), dtype="float32")
    text = (HELLO / "hello.txt").read_text()
    quiet_path = tmp_path / "quiet.wav"
    soundfile.write(str(quiet_path), samples * 0.2, rate)  # 14 dB quieter
    normal = animate(SpeechSpec(audio=HELLO / "hello.flac", text=text), fps=25)
    quiet = animate(SpeechSpec(audio=quiet_path, text=text), fps=25)
    assert [s.name for s in quiet.timeline] == [s.name for s in normal.timeline]
    a, b = normal.track.values[:, JAW], quiet.track.values[:, JAW]
    assert b.max() < 0.85 * a.max()
    assert np.percentile(b[a > 100] / a[a > 100], 50) < 0.85
