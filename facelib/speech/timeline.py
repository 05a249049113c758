"""Phone and word timelines of speech, in integer milliseconds.

A timeline is plain frozen data; each step (alignment, duration model, synthesis) returns a
new one. Visemes are added by :mod:`facelib.visemes`, which reads these.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

from facelib.errors import ParameterError

__all__ = ["SILENCE", "Alphabet", "PhoneTimeline", "Source", "Span", "check_interval"]

SILENCE = "SIL"
"""The phone label of silence (and of the acoustic model's noise phones after cleaning)."""

Source = Literal["forced", "recognized", "phone-loop", "durations", "script", "synthesis",
                 "dtw", "acoustic"]
Alphabet = Literal["arpabet", "ipa"]
"""How phone labels are written: ARPAbet (pocketsphinx, the duration model) or IPA
(espeak-ng synthesis and the alignment built on it)."""


@dataclass(frozen=True, slots=True)
class Span:
    """A labelled interval ``[start_ms, end_ms)``: a phone (ARPAbet without stress or IPA,
    silence as ``"SIL"``) or a word (lower case, silence as ``"SIL"``). ``confidence``: how
    sure recognition is of a word it heard (its posterior probability, 0-1); None where the
    label was given (a transcript) or not judged."""

    label: str
    start_ms: int
    end_ms: int
    confidence: float | None = None

    def __post_init__(self) -> None:
        check_interval(self.label, self.start_ms, self.end_ms)
        if self.confidence is not None and not 0.0 <= self.confidence <= 1.0:
            raise ParameterError(f"span {self.label!r} confidence must be in [0, 1], "
                                 f"got {self.confidence!r}")

    @property
    def duration_ms(self) -> int:
        return self.end_ms - self.start_ms

    def shifted(self, offset_ms: int) -> Span:
        return replace(self, start_ms=self.start_ms + offset_ms, end_ms=self.end_ms + offset_ms)


@dataclass(frozen=True, slots=True)
class PhoneTimeline:
    """What is said when: ``phones`` and ``words`` (spans in time order), how it was found
    (``source``: ``"forced"`` alignment, ``"phone-loop"`` recognition, ``"durations"`` of the
    text-only model, ``"synthesis"`` by espeak-ng, ``"dtw"`` alignment to a synthesized
    transcript, ``"recognized"``: words recognised in audio without a transcript, then
    aligned; ``"acoustic"``: the acoustic viseme model, phones standing for their visemes),
    ``duration_ms``, the length of the speech, and ``alphabet``, how the phone
    labels are written (``"arpabet"`` or ``"ipa"``)."""

    phones: tuple[Span, ...]
    words: tuple[Span, ...]
    source: Source
    duration_ms: int
    alphabet: Alphabet = "arpabet"


def check_interval(label: str, start_ms: int, end_ms: int) -> None:
    """ParameterError unless ``start_ms <= end_ms`` are integers."""
    if not (isinstance(start_ms, int) and isinstance(end_ms, int)):
        raise ParameterError(
            f"span {label!r} times must be integer milliseconds, got {start_ms!r}, {end_ms!r}"
        )
    if end_ms < start_ms:
        raise ParameterError(f"span {label!r} ends ({end_ms} ms) before it starts ({start_ms} ms)")


def append_span(spans: list[Span], label: str, start: int, end: int, *,
                confidence: float | None = None) -> None:
    """Append ``[start, end)`` to ``spans`` (in place), clipped to begin where they end:
    empty spans are dropped, consecutive silences joined and gaps filled with silence.
    ``confidence`` goes with the span appended (not with a silence)."""
    if spans:
        start = max(start, spans[-1].end_ms)
    if end <= start:
        return
    if spans and label == SILENCE and spans[-1].label == SILENCE:
        spans[-1] = Span(SILENCE, spans[-1].start_ms, end)
    elif spans and spans[-1].end_ms < start:
        append_span(spans, SILENCE, spans[-1].end_ms, start)
        append_span(spans, label, start, end, confidence=confidence)
    else:
        spans.append(Span(label, start, end, None if label == SILENCE else confidence))


def cover(spans: list[Span], duration_ms: int) -> tuple[Span, ...]:
    """``spans`` with silence filling the time before the first and after the last, up to
    ``duration_ms``."""
    out: list[Span] = []
    if spans and spans[0].start_ms > 0:
        out.append(Span(SILENCE, 0, spans[0].start_ms))
    for span in spans:
        append_span(out, span.label, span.start_ms, span.end_ms, confidence=span.confidence)
    if out and out[-1].end_ms < duration_ms:
        append_span(out, SILENCE, out[-1].end_ms, duration_ms)
    return tuple(out)
