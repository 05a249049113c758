"""Pass 1 with Whisper (the asr extra): a Festival sentence recognised to its words."""

from __future__ import annotations

from pathlib import Path

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
