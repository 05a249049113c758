"""Forced alignment with pocketsphinx on committed Festival fixtures (exact phones known)."""

from __future__ import annotations

import difflib
import warnings
from pathlib import Path

import numpy as np
import pytest
import soundfile

from facelib.errors import PronunciationWarning, SpeechError
from facelib.visemes import SpeechWarning, align, timeline_to_json

pytestmark = pytest.mark.speech

pytest.importorskip("pocketsphinx")

FIXTURES = Path(__file__).parents[1] / "data" / "speech" / "alignment"


def load_truth(name: str) -> tuple[str, list[tuple[str, float]]]:
    lines = (FIXTURES / f"{name}.tsv").read_text().splitlines()
    text = lines[0].split(": ", 1)[1]
    return text, [(line.split("\t")[0], float(line.split("\t")[1])) for line in lines[1:]]


def onset_errors(name: str) -> np.ndarray:
    """|aligned - true| phone onsets in whole ms (Festival's times are multiples of 5 ms)."""
    text, truth = load_truth(name)
    with warnings.catch_warnings():
        warnings.simplefilter("error", SpeechWarning)  # a correct transcript is plausible
        warnings.simplefilter("ignore", PronunciationWarning)  # made-up names are guessed
        timeline = align(FIXTURES / f"{name}.flac", text)
    truth = [t for t in truth if t[0] != "SIL"]
    got = [p for p in timeline.phones if p.label != "SIL"]
    matcher = difflib.SequenceMatcher(a=[t[0] for t in truth], b=[p.label for p in got],
                                      autojunk=False)
    errors = [got[b.b + i].start_ms - round(1000 * truth[b.a + i][1])
              for b in matcher.get_matching_blocks() for i in range(b.size)]
    assert len(errors) >= 0.85 * len(truth)
    return np.abs(np.array(errors))


@pytest.mark.parametrize("name", ["quick_fox", "oov_names"])
def test_phone_onsets_match_festival_truth(name):
    err = onset_errors(name)  # measured: within 20 ms 100 % / 91 %, mean 6.5 / 9.1 ms
    assert np.mean(err <= 20) >= 0.85
    assert np.mean(err <= 50) >= 0.95
    assert np.median(err) <= 10
    assert err.mean() <= 12


def test_oov_words_get_guessed_pronunciations():
    text, _ = load_truth("oov_names")
    with pytest.warns(PronunciationWarning, match="'zorblat', 'quixotl', 'glimmerfen'"):
        timeline = align(FIXTURES / "oov_names.flac", text)
    words = [w.label for w in timeline.words if w.label != "SIL"]
    assert words == ["zorblat", "met", "quixotl", "near", "the", "glimmerfen", "bridge"]
    zorblat = timeline.words[[w.label for w in timeline.words].index("zorblat")]
    assert abs(zorblat.start_ms - 175) <= 30


def test_json_layout_seconds_and_sil():
    text, _ = load_truth("quick_fox")
    data = timeline_to_json(align(FIXTURES / "quick_fox.flac", text))
    assert data["phones"][0]["phone"] == "SIL"
    assert {"phone", "start", "end"} == set(data["phones"][1])
    assert data["words"][1]["word"] == "the"
    assert data["visemes"][-1]["name"] == "sil"
    assert data["phones"][-1]["end"] == pytest.approx(data["duration"], abs=0.001)
    assert all(p["end"] <= data["duration"] + 1e-9 for p in data["phones"])


def test_dropped_word_is_flagged_by_name():
    with pytest.raises(SpeechError, match="'the'"):
        align(FIXTURES / "quick_fox.flac", "The quick brown fox jumps over the dog.",
              on_implausible="raise")
    with pytest.warns(SpeechWarning, match="after word 'lazy'"):
        align(FIXTURES / "quick_fox.flac", "The quick brown fox jumps over the lazy")


def test_wrong_transcript_is_not_silent():
    with pytest.warns(SpeechWarning, match="sounds like speech"):
        align(FIXTURES / "quick_fox.flac", "Please call Stella.")


def test_any_rate_and_channels(tmp_path):
    data, _rate = soundfile.read(str(FIXTURES / "quick_fox.flac"))
    stereo = tmp_path / "fox_44k.wav"
    from scipy.signal import resample_poly

    up = resample_poly(data, 441, 160)
    soundfile.write(str(stereo), np.stack([up, up], axis=1), 44100)
    text, _ = load_truth("quick_fox")
    a = align(stereo, text)
    b = align(FIXTURES / "quick_fox.flac", text)
    starts_a = [p.start_ms for p in a.phones]
    starts_b = [p.start_ms for p in b.phones]
    assert len(starts_a) == len(starts_b)
    assert np.max(np.abs(np.array(starts_a) - np.array(starts_b))) <= 20


def test_phone_loop_without_transcript():
    from facelib.speech.recognize import recognize
    from facelib.visemes import with_visemes

    timeline = with_visemes(recognize(FIXTURES / "quick_fox.flac", method="phones"))
    assert timeline.source == "phone-loop" and timeline.words == ()
    assert align(FIXTURES / "quick_fox.flac").source == "recognized"  # the default since #34
    speech = [p for p in timeline.phones if p.label != "SIL"]
    assert len(speech) >= 15
    assert timeline.visemes[0].start_ms == 0


def test_silent_empty_and_corrupt_audio(tmp_path):
    silent = tmp_path / "silent.wav"
    soundfile.write(str(silent), np.zeros(16000), 16000)
    with pytest.raises(SpeechError, match="silent"):
        align(silent, "hello")
    empty = tmp_path / "empty.wav"
    soundfile.write(str(empty), np.zeros(0), 16000)
    with pytest.raises(SpeechError, match="empty"):
        align(empty, "hello")
    corrupt = tmp_path / "corrupt.wav"
    corrupt.write_bytes(b"RIFF\x00\x00\x00\x00WAVEjunkjunkjunk")
    with pytest.raises(SpeechError, match=r"corrupt\.wav"):
        align(corrupt, "hello")
    with pytest.raises(SpeechError, match="not found"):
        align(tmp_path / "missing.flac", "hello")
    with pytest.raises(SpeechError, match="no words"):
        align(FIXTURES / "quick_fox.flac", "... !")
