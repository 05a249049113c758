"""Text without a recording: phone durations from a duration model, so lips move plausibly
while a writer drafts a storyboard before the voice is recorded."""

from __future__ import annotations

import warnings

from facelib.checks import check_number
from facelib.errors import MissingExtraError, PronunciationWarning, SpeechError
from facelib.speech.pronounce import letter_to_sound, pronounce, tokenize
from facelib.speech.tables import DurationRules, duration_rules, phone_durations
from facelib.speech.tables import pauses as pause_table
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span

__all__ = ["timeline_from_text"]


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
    rate = check_number("rate", rate, low=0.25, high=4.0)
    pauses = pause_table()
    rules = duration_rules()
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
        start = t
        for phone, ms in _word_durations(_phones_of(token, guessed), token, final=bool(pause),
                                         rate=rate, rules=rules):
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


def _word_durations(
    word_phones: tuple[str, ...], word: str, *, final: bool, rate: float, rules: DurationRules
) -> list[tuple[str, int]]:
    """(phone, ms) of ``word`` spoken as ``word_phones``: each phone's mean duration,
    shortened if it is the vowel of a short one-vowel word, lengthened if it ends a phrase
    (``final``), never below the phone's minimum, scaled by ``rate`` and floored at
    ``rules.floor_ms``."""
    table = phone_durations()
    n_vowels = sum(p in rules.vowels for p in word_phones)
    out = []
    for i, phone in enumerate(word_phones):
        if phone not in table:
            raise SpeechError(f"no duration for phone {phone!r} of word {word!r}")
        mean, least = table[phone]
        short = (phone in rules.vowels and n_vowels == 1
                 and len(word) <= rules.short_word_max_letters)
        factor = rules.short_word_vowel if short else 1.0
        if final and i == len(word_phones) - 1:
            factor *= rules.final_lengthening
        out.append((phone, max(round(max(mean * factor, least) / rate), rules.floor_ms)))
    return out


def _join_silences(spans: list[Span]) -> list[Span]:
    out: list[Span] = []
    for span in spans:
        if out and span.label == SILENCE and out[-1].label == SILENCE:
            out[-1] = Span(SILENCE, out[-1].start_ms, span.end_ms)
        else:
            out.append(span)
    return out
