"""Pass 1 with Whisper (the asr extra): a Festival sentence recognised to its words."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib.speech.audio import load_speech
from facelib.speech.recognize import decode_words, recognize
from facelib.speech.whisper import whisper_model

pytestmark = pytest.mark.speech

pytest.importorskip("faster_whisper")
pytest.importorskip("pocketsphinx")
if whisper_model() is None:
    pytest.skip("no Whisper model package installed", allow_module_level=True)

FIXTURES = Path(__file__).parents[1] / "data" / "speech" / "alignment"


def test_whisper_hears_the_quick_fox():
    words = decode_words(load_speech(FIXTURES / "quick_fox.flac"), decoder="whisper")
    heard = [w.strip(".,").lower() for w, _ in words]
    assert heard == ["the", "quick", "brown", "fox", "jumps", "over", "the", "lazy", "dog"]
    assert all(0.0 <= c <= 1.0 for _, c in words)


def test_two_passes_with_whisper_align_the_words():
    timeline = recognize(FIXTURES / "quick_fox.flac", method="words", decoder="whisper")
    assert timeline.source == "recognized"
    assert [w.label for w in timeline.words if w.label != "SIL"][:3] == ["the", "quick", "brown"]


def test_transcription_resumes_after_whisper_skips_the_rest_of_its_window(monkeypatch):
    """A decoder that hears only the first of three bursts per call (as Whisper does when
    it jumps to its window's end) still yields all three, each once, resumed in the pauses."""
    from types import SimpleNamespace

    from facelib.speech import whisper

    rate = whisper.RATE
    samples = np.zeros(6 * rate, np.float32)
    for second in (0, 2, 4):
        samples[second * rate:(second + 1) * rate] = 0.5
    calls = []

    def first_burst(model, rest, settings):
        calls.append(samples.size - rest.size)
        loud = np.flatnonzero(rest)
        if loud.size == 0:
            return []
        start = loud[0] / rate
        # its end 0.1 s early, as Whisper's last word often is
        return [SimpleNamespace(word=f" w{len(calls)}", probability=0.9, start=start,
                                end=start + 0.9)]

    monkeypatch.setattr(whisper, "_load", lambda name: None)
    monkeypatch.setattr(whisper, "_transcribe", first_burst)
    assert whisper.transcribe_words(samples, model="base") == [
        ("w1", 0.9), ("w2", 0.9), ("w3", 0.9)]
    # resumed within the pauses (1-2 s, 3-4 s, and the last second heard as silence)
    assert len(calls) == 4 and all(samples[c] == 0 for c in calls[1:])
