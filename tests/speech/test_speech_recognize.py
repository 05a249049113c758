"""Speech without a transcript: words decoded then aligned (two passes), the phone-loop
fallback, per-word confidences, and the same path from the API, the CLI and a storyboard."""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path

import numpy as np
import pytest
import soundfile

import facelib
from facelib.cli import main
from facelib.cues import SpeechSpec
from facelib.errors import SpeechError
from facelib.speech.recognize import piece_bounds, recognize
from facelib.visemes import align, animate, speech_timeline, with_visemes

pytestmark = pytest.mark.speech

pytest.importorskip("pocketsphinx")

FIXTURES = Path(__file__).parents[1] / "data" / "speech" / "alignment"
RATE = 16000


def _truth_bilabials(name: str) -> list[tuple[int, int]]:
    """(start_ms, end_ms) of the p/b/m phones in a Festival fixture's exact phones."""
    rows = [line.split("\t") for line in (FIXTURES / f"{name}.tsv").read_text().splitlines()[1:]]
    return [(round(1000 * float(a)), round(1000 * float(b)))
            for label, a, b in rows if label in ("P", "B", "M")]


def _closures_found(truth: list[tuple[int, int]], visemes) -> tuple[int, int]:
    """(truth closures a PP span overlaps, PP spans that overlap no truth closure)."""
    got = [(v.start_ms, v.end_ms) for v in visemes if v.is_bilabial]

    def hit(x, ys):
        return any(x[0] - 20 < y[1] and y[0] < x[1] + 20 for y in ys)

    return sum(hit(x, got) for x in truth), sum(not hit(y, truth) for y in got)


def _tone(seconds: float = 1.0) -> np.ndarray:
    t = np.arange(round(seconds * RATE)) / RATE
    return 0.3 * np.sin(2 * np.pi * 440 * t)


def test_festival_sentence_without_text_closes_on_every_pbm():
    """'The quick brown fox jumps over the lazy dog.' (Festival, exact phones): the two
    passes find the b of brown and the m p of jumps, and no other closure."""
    timeline = align(FIXTURES / "quick_fox.flac")
    assert timeline.source == "recognized"
    truth = _truth_bilabials("quick_fox")
    found, false = _closures_found(truth, timeline.visemes)
    assert (found, false) == (len(truth), 0)
    spoken = [w for w in timeline.words if w.label != "SIL"]
    assert len(spoken) >= 7
    assert all(w.confidence is not None and 0.0 <= w.confidence <= 1.0 for w in spoken)
    assert all(w.confidence is None for w in timeline.words if w.label == "SIL")


def test_many_bilabials_without_text():
    """'Bob made a map of the big pump by the moor.' (Festival): of its 11 p/b/m phones
    (measured: 10 closed, none false; 'pump by' was heard as 'come to buy')."""
    timeline = with_visemes(recognize(FIXTURES / "bilabials.flac"))
    assert timeline.source == "recognized"
    truth = _truth_bilabials("bilabials")
    found, false = _closures_found(truth, timeline.visemes)
    assert len(truth) == 11 and found >= 9 and false <= 1


def test_phone_loop_takes_over_when_no_word_is_heard():
    """A steady 440 Hz tone: the word decoder hears no word, the phone loop hears a
    sound, so ``auto`` gives phones without words; ``words`` alone refuses."""
    timeline = recognize(_tone(), sample_rate=RATE)
    assert timeline.source == "phone-loop" and timeline.words == ()
    assert any(p.label != "SIL" for p in timeline.phones)
    with pytest.raises(SpeechError, match="no word recognised"):
        recognize(_tone(), sample_rate=RATE, method="words")
    loop = recognize(FIXTURES / "quick_fox.flac", method="phones")
    assert loop.source == "phone-loop" and loop.words == ()


def test_other_languages_take_the_acoustic_model():
    """pocketsphinx's paths know English only; ``auto`` hears any other language with the
    acoustic viseme model."""
    with pytest.raises(SpeechError, match=r"speech in 'es' needs its transcript.*knows en"):
        recognize(FIXTURES / "quick_fox.flac", language="es", method="words")
    with pytest.raises(SpeechError, match="'de'"):
        facelib.visemes_from_audio(FIXTURES / "quick_fox.flac", language="de", method="phones")
    heard = facelib.visemes_from_audio(FIXTURES / "quick_fox.flac", language="de")
    assert heard.speech.source == "acoustic" and heard.speech.alphabet == "ipa"
    assert any(v.is_bilabial for v in heard.timeline)


def test_visemes_from_audio_array_is_the_storyboard_path():
    """``visemes_from_audio`` of an array gives the FAP track that ``say { audio = ... }``
    without text gives for the same recording, with coarticulation and closures."""
    samples, rate = soundfile.read(str(FIXTURES / "quick_fox.flac"))
    made = facelib.visemes_from_audio(samples, sample_rate=rate, fps=25)
    spec = SpeechSpec(audio=FIXTURES / "quick_fox.flac")
    said = animate(spec, fps=25)
    assert made.speech.source == said.speech.source == "recognized"
    np.testing.assert_array_equal(made.track.values, said.track.values)
    np.testing.assert_array_equal(made.track.weight, said.track.weight)
    assert [w.confidence for w in made.speech.words] == [w.confidence for w in said.speech.words]
    assert speech_timeline(spec).visemes == said.timeline
    assert sum(v.is_bilabial for v in made.timeline) == 2  # the b of brown, m p of jumps


def test_align_cli_without_text_reports_confidences(tmp_path):
    out = tmp_path / "fox.json"
    assert main(["align", str(FIXTURES / "quick_fox.flac"), "-o", str(out)]) == 0
    data = json.loads(out.read_text())
    assert data["source"] == "recognized"
    words = [w for w in data["words"] if w["word"] != "SIL"]
    assert words and all(0.0 <= w["confidence"] <= 1.0 for w in words)
    assert all("confidence" not in w for w in data["words"] if w["word"] == "SIL")
    tsv = tmp_path / "fox.tsv"
    assert main(["align", str(FIXTURES / "quick_fox.flac"), "-o", str(tsv)]) == 0
    rows = [r.split("\t") for r in tsv.read_text().splitlines()[1:]]
    assert all(0 <= float(r[5]) <= 1 for r in rows if r[0] == "word" and r[1] != "SIL")
    loop = tmp_path / "loop.json"
    assert main(["align", str(FIXTURES / "quick_fox.flac"), "--recognize", "phones", "-o",
                 str(loop)]) == 0
    assert json.loads(loop.read_text())["source"] == "phone-loop"


def test_storyboard_audio_without_text(tmp_path):
    fdl = tmp_path / "fox.fdl"
    (tmp_path / "fox.flac").write_bytes((FIXTURES / "quick_fox.flac").read_bytes())
    fdl.write_text('fps = 25\nsay { audio = "fox.flac" }\n')
    animation = facelib.run_fdl(fdl)
    assert sum(v.is_bilabial for v in animation.visemes) == 2


def test_long_audio_is_cut_in_its_quietest_moment():
    """70 s of a tone with silences at 24-25 s and 50-50.5 s: pieces of at most 30 s cut
    inside each silence."""
    tone = np.tile(_tone(1.0), 70)
    for a, b in ((24.0, 25.0), (50.0, 50.5)):
        tone[round(a * RATE):round(b * RATE)] = 0.0
    bounds = piece_bounds(tone)
    assert [b for _, b in bounds][:-1] == [pytest.approx(24500, abs=300),
                                           pytest.approx(50250, abs=200)]
    assert bounds[0][0] == 0 and bounds[-1][1] == 70000
    assert all(b - a <= 30000 for a, b in bounds)


@pytest.mark.slow
def test_long_recording_is_recognised_in_pieces():
    """Eleven readings of the fox sentence with 0.6 s pauses (40 s): two pieces, words
    in both, times continuous across the cut, 22 closures (two per reading)."""
    samples, rate = soundfile.read(str(FIXTURES / "quick_fox.flac"))
    gap = np.zeros(round(0.6 * rate))
    long = np.concatenate([np.concatenate([samples, gap]) for _ in range(11)])
    assert rate == RATE and len(piece_bounds(long)) == 2
    timeline = with_visemes(recognize(long, sample_rate=rate))
    assert timeline.source == "recognized"
    assert timeline.phones[-1].end_ms == timeline.duration_ms == round(1000 * long.size / rate)
    assert all(a.end_ms == b.start_ms for a, b in pairwise(timeline.phones))
    spoken = [w for w in timeline.words if w.label != "SIL"]
    assert spoken[0].start_ms < 1000 and spoken[-1].end_ms > timeline.duration_ms - 3000
    assert 20 <= sum(v.is_bilabial for v in timeline.visemes) <= 24
