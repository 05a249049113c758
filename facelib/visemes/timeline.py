"""Speech timelines: phone, word and viseme spans in integer milliseconds.

A timeline is a chain of plain frozen records; each processing step (alignment, duration
model, phone -> viseme mapping, minimum-duration rules) takes one and returns a new one.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

from facelib.errors import ParameterError

__all__ = ["SILENCE", "Source", "Span", "SpeechTimeline", "VisemeSpan"]

SILENCE = "SIL"
"""The phone label of silence (and of the acoustic model's noise phones after cleaning)."""

Source = Literal["forced", "phone-loop", "durations", "script"]


@dataclass(frozen=True, slots=True)
class Span:
    """A labelled interval ``[start_ms, end_ms)``: a phone (ARPAbet without stress, silence
    as ``"SIL"``) or a word (lower case, silence as ``"SIL"``)."""

    label: str
    start_ms: int
    end_ms: int

    def __post_init__(self) -> None:
        _check_interval(self.label, self.start_ms, self.end_ms)

    @property
    def duration_ms(self) -> int:
        return self.end_ms - self.start_ms

    def shifted(self, offset_ms: int) -> Span:
        return replace(self, start_ms=self.start_ms + offset_ms, end_ms=self.end_ms + offset_ms)


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
        _check_interval(self.name, self.start_ms, self.end_ms)

    @property
    def duration_ms(self) -> int:
        return self.end_ms - self.start_ms

    @property
    def is_silence(self) -> bool:
        return self.viseme == 0

    def shifted(self, offset_ms: int) -> VisemeSpan:
        return replace(self, start_ms=self.start_ms + offset_ms, end_ms=self.end_ms + offset_ms)


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
    """

    phones: tuple[Span, ...]
    words: tuple[Span, ...]
    visemes: tuple[VisemeSpan, ...]
    source: Source
    duration_ms: int

    def shifted(self, offset_ms: int) -> SpeechTimeline:
        """The same timeline ``offset_ms`` later."""
        return SpeechTimeline(
            tuple(s.shifted(offset_ms) for s in self.phones),
            tuple(s.shifted(offset_ms) for s in self.words),
            tuple(s.shifted(offset_ms) for s in self.visemes),
            self.source,
            self.duration_ms,
        )


def _check_interval(label: str, start_ms: int, end_ms: int) -> None:
    if not (isinstance(start_ms, int) and isinstance(end_ms, int)):
        raise ParameterError(
            f"span {label!r} times must be integer milliseconds, got {start_ms!r}, {end_ms!r}"
        )
    if end_ms < start_ms:
        raise ParameterError(f"span {label!r} ends ({end_ms} ms) before it starts ({start_ms} ms)")
