"""Text without a recording: phone durations from a duration model, so lips move plausibly
while a writer drafts a storyboard before the voice is recorded."""

from __future__ import annotations

import warnings

from facelib.errors import (
    MissingExtraError,
    ParameterError,
    PronunciationWarning,
    SpeechError,
)
from facelib.speech.pronounce import letter_to_sound, pronounce, tokenize
from facelib.speech.tables import pauses as pause_table
from facelib.speech.tables import phone_durations
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span

__all__ = ["FINAL_LENGTHENING", "SHORT_WORD_VOWEL", "timeline_from_text"]

FINAL_LENGTHENING = 1.4
"""Phrase-final lengthening of the last phone before a pause (Klatt 1979 rule: x1.4)."""
SHORT_WORD_VOWEL = 0.7
"""Vowels of short one-vowel words (a, the, of, to, is, ...), usually unstressed, shortened."""
_VOWELS = frozenset(
    ("AA", "AE", "AH", "AO", "AW", "AY", "EH", "ER", "EY", "IH", "IY", "OW", "OY", "UH", "UW")
)


def _phones_of(word: str, guessed: list[str]) -> tuple[str, ...]:
    try:
        phones, known = pronounce(word)
    except MissingExtraError:  # no dictionary without the speech extra: spell it out
        phones, known = letter_to_sound(word), False
    if not known:
        guessed.append(word)
    return phones


def timeline_from_text(text: str, *, rate: float = 1.0) -> PhoneTimeline:
    """Phones and words of ``text`` spoken at ``rate`` (1.0 is about 160 words per
    minute; 2.0 twice as fast), from the duration model (``phone_durations.csv``, pauses at
    punctuation from ``pauses.csv``). Times in ms from 0; ``source="durations"``."""
    if not (isinstance(rate, (int, float)) and 0.25 <= rate <= 4):
        raise ParameterError(f"speaking rate must be between 0.25 and 4, got {rate!r}")
    pauses = pause_table()
    table = phone_durations()
    tokens = tokenize(text)
    guessed: list[str] = []
    phones: list[Span] = []
    words: list[Span] = []
    t = round(pauses["edge"] / rate)
    phones.append(Span(SILENCE, 0, t))
    words.append(Span(SILENCE, 0, t))
    for k, token in enumerate(tokens):
        if not token[0].isalpha():
            continue
        following = tokens[k + 1] if k + 1 < len(tokens) else None
        pause = pauses.get(following, 0) if following else pauses["edge"]
        word_phones = _phones_of(token, guessed)
        n_vowels = sum(p in _VOWELS for p in word_phones)
        start = t
        for i, phone in enumerate(word_phones):
            if phone not in table:
                raise SpeechError(f"no duration for phone {phone!r} of word {token!r}")
            mean, least = table[phone]
            factor = SHORT_WORD_VOWEL if (phone in _VOWELS and n_vowels == 1
                                          and len(token) <= 3) else 1.0
            if pause and i == len(word_phones) - 1:
                factor *= FINAL_LENGTHENING
            ms = max(round(max(mean * factor, least) / rate), 10)
            phones.append(Span(phone, t, t + ms))
            t += ms
        words.append(Span(token, start, t))
        if pause:
            ms = round(pause / rate)
            phones.append(Span(SILENCE, t, t + ms))
            words.append(Span(SILENCE, t, t + ms))
            t += ms
    if guessed:
        warnings.warn(f"not in the pronunciation dictionary, pronounced as spelt: "
                      f"{', '.join(repr(w) for w in dict.fromkeys(guessed))}", PronunciationWarning,
                      stacklevel=2)
    phones = _join_silences(phones)
    words = _join_silences(words)
    return PhoneTimeline(tuple(phones), tuple(words), "durations", t)


def _join_silences(spans: list[Span]) -> list[Span]:
    out: list[Span] = []
    for span in spans:
        if out and span.label == SILENCE and out[-1].label == SILENCE:
            out[-1] = Span(SILENCE, out[-1].start_ms, span.end_ms)
        else:
            out.append(span)
    return out
