"""Long English recordings: cut at sentences found by DTW, each piece aligned by
pocketsphinx, results stitched (bounded memory, linear time)."""

import difflib
import importlib
import itertools
import warnings

import numpy as np
import pytest
import soundfile

from facelib.cli import main
from facelib.speech import synthesize

align_module = importlib.import_module("facelib.speech.align")
pytestmark = pytest.mark.speech
TEXT = ("Bob bought a big map of the moon. The quick brown fox jumps over the lazy dog. "
        "Please remember to bring both maps when you come back on Monday.")


def test_recording_is_aligned_in_pieces_like_a_short_one(tmp_path, monkeypatch):
    recording = synthesize(TEXT, lang="en", voice="en-us+m3")
    path = tmp_path / "three.wav"
    soundfile.write(path, np.asarray(recording.samples), recording.sample_rate)
    monkeypatch.setattr(align_module, "LONG_MS", 2000)  # treat it as a long recording
    found = []
    dtw = importlib.import_module("facelib.speech.dtw")
    real = dtw.sentence_spans
    monkeypatch.setattr(dtw, "sentence_spans", lambda *a, **k: found.extend(real(*a, **k))
                        or found)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pieces = align_module.align(path, TEXT)
    assert [s.label for s in found] == [
        "Bob bought a big map of the moon.", "The quick brown fox jumps over the lazy dog.",
        "Please remember to bring both maps when you come back on Monday."]
    words = [w.label for w in pieces.words if w.label != "SIL"]
    assert words[:3] == ["bob", "bought", "a"] and words[-2:] == ["on", "monday"]
    assert len(words) == len(TEXT.split())
    assert pieces.duration_ms == pieces.phones[-1].end_ms
    assert all(a.end_ms == b.start_ms for a, b in itertools.pairwise(pieces.phones))
    truth = [w for w in recording.timeline.words if w.label != "SIL"]
    got = [w for w in pieces.words if w.label != "SIL"]
    matcher = difflib.SequenceMatcher(a=[w.label.strip(".,") for w in truth],
                                      b=[w.label for w in got], autojunk=False)
    errors = [abs(truth[m.a + k].start_ms - got[m.b + k].start_ms)
              for m in matcher.get_matching_blocks() for k in range(m.size)]
    assert len(errors) >= 0.9 * len(truth)
    assert np.mean(np.array(errors) <= 60) >= 0.85


def test_cli_lists_voices_and_languages(capsys):
    assert main(["list", "voices", "--lang", "de"]) == 0
    out = capsys.readouterr().out
    assert "gmw/de" in out and "German" in out
    assert main(["list", "languages"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert {line.split()[0] for line in lines} == {"en", "es", "pt", "fr", "de", "it"}
