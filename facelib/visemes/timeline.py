"""Speech timelines with visemes: the phone and word spans of :mod:`facelib.speech` plus the
viseme spans made from them, in integer milliseconds."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from facelib.errors import ParameterError
from facelib.speech.timeline import (
    SILENCE,
    Alphabet,
    PhoneTimeline,
    Source,
    Span,
    check_interval,
)

__all__ = ["SILENCE", "Alphabet", "PhoneTimeline", "Source", "Span", "SpeechTimeline",
           "VisemeSpan", "bilabial_spans"]


@dataclass(frozen=True, slots=True)
class VisemeSpan:
    """MPEG-4 viseme ``viseme`` (0-14, named ``name``) shown over ``[start_ms, end_ms)``,
    made from ``phones`` (empty for a stored viseme script)."""

    viseme: int
    name: str
    start_ms: int
    end_ms: int
    phones: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if not 0 <= self.viseme <= 14:
            raise ParameterError(f"viseme id must be 0-14, got {self.viseme!r}")
        check_interval(self.name, self.start_ms, self.end_ms)

    @property
    def duration_ms(self) -> int:
        return self.end_ms - self.start_ms

    @property
    def is_silence(self) -> bool:
        return self.viseme == 0

    @property
    def is_bilabial(self) -> bool:
        """MPEG-4 viseme 1 (p, b, m): the lips close."""
        return self.viseme == 1

    def shifted(self, offset_ms: int) -> VisemeSpan:
        return replace(self, start_ms=self.start_ms + offset_ms, end_ms=self.end_ms + offset_ms)


def bilabial_spans(visemes: Sequence[VisemeSpan] | None) -> list[tuple[int, int]]:
    """``(start_ms, end_ms)`` of the p, b and m visemes among ``visemes`` (an animation's
    viseme track; None, an animation without speech, has none)."""
    return [(v.start_ms, v.end_ms) for v in visemes or () if v.is_bilabial]


@dataclass(frozen=True, slots=True)
class SpeechTimeline:
    """What is said when: phones, words and visemes, each in time order.

    Attributes
    ----------
    phones: phone spans (empty for a stored viseme script).
    words: word spans (empty for phone-loop recognition and viseme scripts).
    visemes: viseme spans covering the same time as the phones.
    source: how it was made: ``"forced"`` alignment of audio and transcript,
        ``"phone-loop"`` recognition of audio alone, ``"durations"`` (text only, duration
        model) or ``"script"`` (a stored viseme script).
    duration_ms: length of the speech (the audio's length where there is audio).
    alphabet: how phone labels are written, ``"arpabet"`` or ``"ipa"``.
    """

    phones: tuple[Span, ...]
    words: tuple[Span, ...]
    visemes: tuple[VisemeSpan, ...]
    source: Source
    duration_ms: int
    alphabet: Alphabet = "arpabet"

    def shifted(self, offset_ms: int) -> SpeechTimeline:
        """The same timeline ``offset_ms`` later."""
        return SpeechTimeline(
            tuple(s.shifted(offset_ms) for s in self.phones),
            tuple(s.shifted(offset_ms) for s in self.words),
            tuple(s.shifted(offset_ms) for s in self.visemes),
            self.source,
            self.duration_ms,
            self.alphabet,
        )
