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
    t = np.arange(16000) / 16000
    loud = (0.3 * np.sin(2 * np.pi * 200 * t)).astype(np.float32)  # about -13 dBFS
    times = np.array([-100.0, 500.0, 2000.0])
    gain = jaw_gain(loud, times, start_ms=0.0, rules=rules)
    assert gain[0] == 1.0 and gain[2] == 1.0  # before and after the audio
    assert 1.2 < gain[1] <= rules["max_gain"]
    quiet = jaw_gain(loud * 0.05, times, start_ms=0.0, rules=rules)[1]  # about -39 dBFS
    assert quiet == pytest.approx(rules["min_gain"])


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
