"""espeak-ng synthesis: audio, phone times, languages, voices, repeatability."""

import numpy as np
import pytest

from facelib.cues import SpeechSpec
from facelib.errors import ParameterError, SpeechError
from facelib.mpeg4.tables import fap
from facelib.speech import list_voices, synthesize
from facelib.speech.synth import languages
from facelib.visemes import animate
from facelib.visemes.ipa import ipa_viseme
from facelib.visemes.mapping import phones_to_visemes
from facelib.visemes.tables import viseme_targets

pytestmark = pytest.mark.speech
LANGS = sorted(languages())
FPS = 25.0


def test_six_languages_are_tested():
    assert set(LANGS) >= {"en", "es", "pt", "fr", "de", "it"}


@pytest.mark.parametrize("lang", LANGS)
def test_every_phone_maps_to_a_viseme(lang):
    made = synthesize(languages()[lang].sentence, lang=lang)
    spoken = [p.label for p in made.timeline.phones if p.label != "SIL"]
    assert len(spoken) > 20
    for label in spoken:
        rule = ipa_viseme(label)  # raises on a symbol missing from the table
        assert all(0 < v < 15 for v in rule.visemes), label
    assert made.timeline.alphabet == "ipa" and made.timeline.source == "synthesis"


@pytest.mark.parametrize("lang", LANGS)
def test_visemes_follow_espeaks_own_phone_times(lang):
    sentence = languages()[lang].sentence
    made = synthesize(sentence, lang=lang)
    anim = animate(SpeechSpec(text=sentence, lang=lang, start_ms=0), fps=FPS)
    # the animation speaks exactly what espeak-ng made, to the sample
    assert anim.speech.phones == made.timeline.phones
    assert np.array_equal(anim.audio.samples, made.samples)
    # boundaries of espeak's phones (and of the two halves of its diphthongs)
    onsets = {v.start_ms for v in phones_to_visemes(made.timeline.phones, alphabet="ipa")}
    frame = 1000 / FPS
    for span in anim.timeline:
        if span.is_silence:  # a short final pause may be stretched to stay visible
            continue
        nearest = min(onsets, key=lambda t: abs(t - span.start_ms))
        assert abs(nearest - span.start_ms) <= frame, span


@pytest.mark.parametrize("lang", LANGS)
def test_lips_close_on_the_bilabials(lang):
    """Inside every p/b/m the upper lip is at the closure's height and the lower lip at the
    closure's plus the jaw's extra opening: the lips meet whatever the jaw does."""
    sentence = languages()[lang].sentence
    anim = animate(SpeechSpec(text=sentence, lang=lang), fps=FPS)
    closed = viseme_targets()[1]
    upper = [fap(n).index for n in ("lower_t_midlip", "lower_t_lip_lm", "lower_t_lip_rm")]
    lower = [fap(n).index for n in ("raise_b_midlip", "raise_b_lip_lm", "raise_b_lip_rm")]
    jaw = fap("open_jaw").index
    times = np.arange(anim.track.n_frames) * 1000 / FPS
    checked = 0
    for span in anim.timeline:
        if span.viseme != 1:
            continue
        for i in np.flatnonzero((times >= span.start_ms) & (times < span.end_ms)):
            v = anim.track.values[i]
            assert np.allclose(v[upper], closed[upper], atol=0.5)
            # (the lower lip drops lower_lip_per_jaw MNS per jaw unit on the default head)
            from facelib.visemes.tables import lower_lip_per_jaw

            extra = lower_lip_per_jaw() * max(v[jaw] - closed[jaw], 0.0)
            assert np.allclose(v[lower], closed[lower] + extra, atol=0.5)
            checked += 1
    assert checked >= 3


def test_rate_and_pitch_change_the_speech():
    base = synthesize("Bob bought a big map.")
    fast = synthesize("Bob bought a big map.", rate=1.6)
    high = synthesize("Bob bought a big map.", pitch=90)
    assert fast.timeline.duration_ms < 0.8 * base.timeline.duration_ms
    assert [p.label for p in fast.timeline.phones if p.label != "SIL"] == \
        [p.label for p in base.timeline.phones if p.label != "SIL"]
    assert not np.array_equal(high.samples, base.samples)


def test_same_text_same_samples_bit_for_bit():
    a = synthesize("Olá, tudo bem?", lang="pt")
    synthesize("Something else first.", lang="en")
    b = synthesize("Olá, tudo bem?", lang="pt")
    assert np.array_equal(a.samples, b.samples) and a.timeline == b.timeline


def test_audio_is_speech_not_silence():
    made = synthesize("Hello there.")
    assert made.sample_rate == 22050
    assert made.samples.dtype == np.float32 and not made.samples.flags.writeable
    rms = float(np.sqrt(np.mean(made.samples.astype(np.float64) ** 2)))
    assert rms > 0.02
    assert made.timeline.duration_ms == round(made.samples.size * 1000 / made.sample_rate)


def test_voices_are_listed_and_usable():
    voices = list_voices()
    assert len(voices) > 50
    pt = [v for v in voices if "pt" in v.languages]
    assert pt
    made = synthesize("Olá", lang="pt", voice=pt[0].identifier)
    assert made.voice == pt[0].identifier


def test_bad_arguments():
    with pytest.raises(SpeechError, match="no voice"):
        synthesize("hello", voice="no-such-voice")
    with pytest.raises(ParameterError, match="speaking rate"):
        synthesize("hello", rate=9)
    with pytest.raises(ParameterError, match="non-empty"):
        synthesize("   ")


def test_a_worker_started_ahead_speaks_as_a_fresh_one():
    import time

    from facelib.speech.espeak import Worker

    fresh = synthesize("How are you today?")
    ahead = Worker()
    time.sleep(0.3)  # loaded and waiting when the text comes
    made = synthesize("How are you today?", worker=ahead)
    assert np.array_equal(made.samples, fresh.samples)
    assert made.timeline == fresh.timeline
    with pytest.raises(SpeechError):  # one batch per process
        synthesize("Again.", worker=ahead)
    unused = Worker()
    unused.close()
    unused.close()  # closing twice is harmless
