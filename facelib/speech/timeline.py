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

Source = Literal["forced", "phone-loop", "durations", "script", "synthesis", "dtw"]
Alphabet = Literal["arpabet", "ipa"]
"""How phone labels are written: ARPAbet (pocketsphinx, the duration model) or IPA
(espeak-ng synthesis and the alignment built on it)."""


@dataclass(frozen=True, slots=True)
class Span:
    """A labelled interval ``[start_ms, end_ms)``: a phone (ARPAbet without stress or IPA,
    silence as ``"SIL"``) or a word (lower case, silence as ``"SIL"``)."""

    label: str
    start_ms: int
    end_ms: int

    def __post_init__(self) -> None:
        check_interval(self.label, self.start_ms, self.end_ms)

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
    transcript), ``duration_ms``, the length of the speech, and ``alphabet``, how the phone
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
