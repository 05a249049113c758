"""IPA phones -> visemes, for every language espeak-ng speaks (``ipa_to_viseme.csv``).

A phone label (in IPA; stressed, nasal, long, or with espeak-ng's unstressed "-") is
cleaned of stress, length and diacritics, then read as a sequence of table symbols, longest
match first; a diphthong or cluster gives its symbols' visemes in turn (equal shares of
the phone's time).
"""

from __future__ import annotations

import unicodedata
from collections.abc import Mapping
from functools import cache
from types import MappingProxyType

from facelib import data
from facelib.errors import DataError, ParameterError
from facelib.mpeg4.visemes import N_VISEMES
from facelib.speech.timeline import SILENCE
from facelib.visemes.tables import PhoneViseme

__all__ = ["clean_ipa", "ipa_table", "ipa_viseme"]

_FILE = "visemes/ipa_to_viseme.csv"
_DROP_CATEGORIES = frozenset(("Mn", "Lm", "Sk"))  # combining marks, modifier letters/symbols
_DROP_CHARS = frozenset("-_'|")  # espeak-ng's unstressed mark and separators


@cache
def ipa_table() -> Mapping[str, int]:
    """IPA symbol (one or two characters) -> viseme id, from ``ipa_to_viseme.csv``."""
    table: dict[str, int] = {}
    for line, row in data.csv_rows(_FILE):
        symbol, viseme = row["ipa"], row["viseme"]
        if not symbol or not viseme.isdigit() or not 0 <= int(viseme) < N_VISEMES:
            raise DataError(f"bad row for IPA symbol {symbol!r}: viseme {viseme!r}",
                            path=str(data.path(_FILE)), line=line)
        if not row["source"]:
            raise DataError(f"IPA symbol {symbol!r} has no source", path=str(data.path(_FILE)),
                            line=line)
        table[symbol] = int(viseme)
    return MappingProxyType(table)


def clean_ipa(label: str) -> str:
    """``label`` without stress and length marks, diacritics and espeak-ng's separators."""
    return "".join(ch for ch in unicodedata.normalize("NFD", label)
                   if unicodedata.category(ch) not in _DROP_CATEGORIES and ch not in _DROP_CHARS)


@cache
def ipa_viseme(label: str) -> PhoneViseme:
    """How IPA phone ``label`` is shown (``"SIL"`` or an empty label: silence, viseme 0).

    Raises ParameterError naming the symbol when a symbol is not in the table.
    """
    cleaned = clean_ipa(label)
    if label == SILENCE or not cleaned:
        return PhoneViseme(label, (0,), 1.0)
    table = ipa_table()
    visemes: list[int] = []
    i = 0
    while i < len(cleaned):
        for size in (2, 1):
            symbol = cleaned[i:i + size]
            if len(symbol) == size and symbol in table:
                if not visemes or visemes[-1] != table[symbol]:
                    visemes.append(table[symbol])
                i += size
                break
        else:
            raise ParameterError(
                f"IPA symbol {cleaned[i]!r} (U+{ord(cleaned[i]):04X}) of phone {label!r} has no "
                f"viseme; add it to facelib/data/{_FILE}"
            )
    return PhoneViseme(label, tuple(visemes), 1.0 / len(visemes))
