"""Synthesized speech: text -> audio and its exact phone timeline, in any language
espeak-ng speaks (the ``speech`` extra).

Numbers are spelt out in the text's language first (:mod:`facelib.speech.normalize`);
espeak-ng then speaks the text and reports each phone (IPA) and word as it makes the audio,
so the phone times are those of the samples returned, to the sample.
"""

from __future__ import annotations

import re
from bisect import bisect_left
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType

import numpy as np

from facelib import data
from facelib.checks import check_number
from facelib.errors import ParameterError, SpeechError
from facelib.speech.espeak import (
    EspeakEvent,
    Worker,
    default_words_per_minute,
    list_voices,
    synth_fresh,
)
from facelib.speech.normalize import spell_numbers
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span, append_span, cover

__all__ = ["DEFAULT_LANGUAGE", "Language", "Synthesis", "languages", "list_voices",
           "synthesize", "synthesize_many", "voice_for"]

DEFAULT_LANGUAGE = "en"
"""The language of speech when neither the speech nor the storyboard names one."""
_STRESS = re.compile("[ˈˌ]")
_MIN_WPM, _MAX_WPM = 80, 450


@dataclass(frozen=True, slots=True)
class Language:
    """A tested language (``languages.csv``): storyboard code ``lang``, espeak-ng ``voice``,
    English ``name`` and a test ``sentence``."""

    lang: str
    voice: str
    name: str
    sentence: str


@dataclass(frozen=True, eq=False)
class Synthesis:
    """Synthesized speech.

    samples: ``(n,) float32`` in [-1, 1], mono, read-only.
    sample_rate: Hz (22050 for espeak-ng).
    timeline: phones (IPA, ``alphabet="ipa"``) and words in ms from the first sample,
        ``source="synthesis"``; ``duration_ms`` is the audio's length.
    text: the text as spoken (numbers spelt out).
    voice: the espeak-ng voice used.
    """

    samples: np.ndarray
    sample_rate: int
    timeline: PhoneTimeline
    text: str
    voice: str


@cache
def languages() -> Mapping[str, Language]:
    """The tested languages of ``languages.csv`` by code."""
    return MappingProxyType({
        row["lang"]: Language(row["lang"], row["voice"], row["name"], row["sentence"])
        for _, row in data.csv_rows("speech/languages.csv")
    })


def voice_for(lang: str) -> str:
    """The espeak-ng voice that speaks ``lang`` (``languages.csv``, else ``lang`` itself)."""
    known = languages().get(lang.lower())
    return known.voice if known else lang


def synthesize(
    text: str,
    *,
    lang: str = DEFAULT_LANGUAGE,
    voice: str | None = None,
    rate: float = 1.0,
    pitch: float = 50,
    worker: Worker | None = None,
) -> Synthesis:
    """Speak ``text`` in language ``lang`` with espeak-ng.

    Parameters
    ----------
    text: what is said (plain text; numbers are spelt out in ``lang`` first).
    lang: language code (``"en"``, ``"pt"``, ``"pt-br"``, ... any espeak-ng language).
    voice: an espeak-ng voice (``"es-419"``, ``"en-us+f3"`` for a variant); default: the
        language's own (``voice_for(lang)``).
    rate: speaking rate, 1.0 = espeak-ng's 175 words per minute; 0.5-2.5.
    pitch: base pitch on espeak-ng's 0-100 scale (50 = the voice's own).
    worker: an espeak-ng process started ahead (:class:`facelib.speech.espeak.Worker`), or
        None to start one now; the result is the same.

    Raises
    ------
    ParameterError: rate or pitch out of range, empty text. SpeechError: unknown voice or
    nothing spoken. MissingExtraError: the ``speech`` extra is not installed.
    """
    if not isinstance(text, str) or not text.strip():
        raise ParameterError(f"text to speak must be a non-empty string, got {text!r}")
    return synthesize_many([text], lang=lang, voice=voice, rate=rate, pitch=pitch,
                           worker=worker)[0]


def synthesize_many(
    texts: Sequence[str],
    *,
    lang: str = DEFAULT_LANGUAGE,
    voice: str | None = None,
    rate: float = 1.0,
    pitch: float = 50,
    voices: Sequence[str] | None = None,
    worker: Worker | None = None,
) -> list[Synthesis]:
    """:func:`synthesize` of each of ``texts`` (same options), in one fresh espeak-ng
    process (:func:`facelib.speech.espeak.synth_fresh`): the result depends only on the
    arguments, bit for bit. ``voices`` gives each text its own voice (overrides ``voice``);
    ``worker``: the process to use, started ahead (see :func:`synthesize`)."""
    for text in texts:
        if not isinstance(text, str) or not text.strip():
            raise ParameterError(f"text to speak must be a non-empty string, got {text!r}")
    rate = check_number("speaking rate", rate, low=0.5, high=2.5)
    pitch = check_number("pitch", pitch, low=0, high=100)
    chosen = list(voices) if voices is not None else [voice or voice_for(lang)] * len(texts)
    if len(chosen) != len(texts):
        raise ParameterError(f"{len(chosen)} voices for {len(texts)} texts")
    wpm = round(min(max(rate * default_words_per_minute(), _MIN_WPM), _MAX_WPM))
    spoken = [spell_numbers(text, lang=lang) for text in texts]
    raws = synth_fresh([(s, v, wpm, round(pitch)) for s, v in zip(spoken, chosen, strict=True)],
                       worker=worker)
    out = []
    for text, said, raw, who in zip(texts, spoken, raws, chosen, strict=True):
        if raw.samples.size == 0 or not any(e.kind == "phone" and e.name for e in raw.events):
            raise SpeechError(f"espeak-ng spoke nothing for {text[:60]!r} (voice {who!r})")
        samples = raw.samples.astype(np.float32) / 32768.0
        samples.flags.writeable = False
        timeline = events_to_timeline(raw.events, said, n_samples=raw.samples.size,
                                      sample_rate=raw.sample_rate)
        out.append(Synthesis(samples, raw.sample_rate, timeline, said, who))
    return out


def events_to_timeline(
    events: Sequence[EspeakEvent], text: str, *, n_samples: int, sample_rate: int
) -> PhoneTimeline:
    """The phone and word timeline of espeak-ng's events for ``text``: phone k lasts from
    its event to the next phone event (pauses, empty names, are silence); a word lasts from
    its WORD event to the end of its last phone. Stress marks are dropped from the IPA."""

    def ms(sample: int) -> int:
        return round(min(max(sample, 0), n_samples) * 1000 / sample_rate)

    phone_events = [e for e in events if e.kind == "phone"]
    bounds = [*(e.sample for e in phone_events), n_samples]
    phones: list[Span] = []
    for e, end in zip(phone_events, bounds[1:], strict=True):
        append_span(phones, _STRESS.sub("", e.name) or SILENCE, ms(e.sample), ms(end))
    duration = ms(n_samples)
    phones = _covered(phones, duration)
    starts = [p.start_ms for p in phones]
    words: list[Span] = []
    word_events = [e for e in events if e.kind == "word"]
    for k, w in enumerate(word_events):
        start = ms(w.sample)
        end = ms(word_events[k + 1].sample) if k + 1 < len(word_events) else duration
        # the word ends where its trailing pause (if any) begins
        k_end = bisect_left(starts, end)
        while k_end > 0 and starts[k_end - 1] >= start and phones[k_end - 1].label == SILENCE:
            k_end -= 1
            end = phones[k_end].start_ms
        if words and words[-1].start_ms == start:  # espeak expanded one token to many
            continue
        label = text[w.text_position - 1:w.text_position - 1 + w.length].strip().lower()
        append_span(words, label or "?", start, end)
    return PhoneTimeline(tuple(phones), tuple(_covered(words, duration)), "synthesis",
                         duration, alphabet="ipa")


def _covered(spans: list[Span], duration_ms: int) -> list[Span]:
    """``spans`` with silence before the first and after the last, up to ``duration_ms``
    (all silence when there are none)."""
    out = list(cover(spans, duration_ms))
    return out or ([Span(SILENCE, 0, duration_ms)] if duration_ms else [])
