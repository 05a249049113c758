"""The speech rules as data: loaders for the files in ``facelib/data/speech/``.

- ``alignment.json``: forced-alignment settings (frame rate, beams, boundary shifts, checks).
- ``recognition.json``: speech without a transcript (word decoding, pieces, languages).
- ``phone_durations.csv``: the text-only duration model.
- ``pauses.csv``: pauses at punctuation for the duration model.
- ``duration_rules.json``: the duration model's rules (vowels, lengthening, floors).
- ``letter_to_sound.csv``: pronunciations for words missing from the dictionary.

Each is read once, on first use, and returned read-only.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from types import MappingProxyType
from typing import Any

from facelib import data
from facelib.errors import DataError

__all__ = [
    "DurationRules",
    "alignment_settings",
    "duration_rules",
    "letter_to_sound_rules",
    "pauses",
    "phone_durations",
    "recognition_settings",
]


@cache
def _alignment() -> Mapping[str, Any]:
    return MappingProxyType(data.json_data("speech/alignment.json"))


def alignment_settings() -> Mapping[str, Any]:
    """The settings of ``alignment.json`` (keys without ``_about``)."""
    return _alignment()


@cache
def _recognition() -> Mapping[str, Any]:
    return MappingProxyType(data.json_data("speech/recognition.json"))


def recognition_settings() -> Mapping[str, Any]:
    """The settings of ``recognition.json`` (keys without ``_about``): speech without a
    transcript."""
    return _recognition()


@cache
def phone_durations() -> Mapping[str, tuple[int, int]]:
    """ARPAbet phone -> (mean_ms, min_ms) at speaking rate 1.0."""
    return MappingProxyType(
        {row["phone"]: (int(row["mean_ms"]), int(row["min_ms"]))
         for _, row in data.csv_rows("speech/phone_durations.csv")}
    )


@cache
def pauses() -> Mapping[str, int]:
    """Punctuation mark (or ``"edge"``) -> pause in ms at speaking rate 1.0."""
    return MappingProxyType(
        {row["mark"]: int(row["pause_ms"]) for _, row in data.csv_rows("speech/pauses.csv")}
    )


@cache
def letter_to_sound_rules() -> tuple[tuple[str, tuple[str, ...]], ...]:
    """(letter group, phones) rules, longest groups first (ties keep file order)."""
    rules = [
        (row["graphemes"], () if row["phones"] == "-" else tuple(row["phones"].split()))
        for _, row in data.csv_rows("speech/letter_to_sound.csv")
    ]
    return tuple(sorted(rules, key=lambda r: -len(r[0])))


@dataclass(frozen=True, slots=True)
class DurationRules:
    """The duration model's rules (``duration_rules.json``, where each is explained)."""

    vowels: frozenset[str]
    final_lengthening: float
    short_word_vowel: float
    short_word_max_letters: int
    floor_ms: int


@cache
def duration_rules() -> DurationRules:
    """The rules of ``duration_rules.json``; DataError if one is missing or malformed."""
    name = "speech/duration_rules.json"
    doc = data.json_data(name)
    try:
        return DurationRules(
            vowels=frozenset(str(v) for v in doc["vowels"]),
            final_lengthening=float(doc["final_lengthening"]),
            short_word_vowel=float(doc["short_word_vowel"]),
            short_word_max_letters=int(doc["short_word_max_letters"]),
            floor_ms=int(doc["floor_ms"]),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"bad duration rules: {exc!r}", path=str(data.path(name))) from exc
