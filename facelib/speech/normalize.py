"""Text normalisation before speech, with libraries rather than rules of our own:
numbers, years, decimals and ordinals spelt out by ``num2words`` in the text's language, and
transliteration to ASCII by ``anyascii`` for the English pronunciation dictionary
("José" -> "jose", "café" -> "cafe"). Both are in the ``speech`` extra.
"""

from __future__ import annotations

import re
from decimal import Decimal
from functools import cache

from facelib.errors import ParameterError
from facelib.optional import require

__all__ = ["num2words_language", "spell_numbers", "to_ascii"]

# a number: digits with optional thousands separators, one decimal part, an ordinal ending
_NUMBER = re.compile(
    r"(?<![\w.,])(?P<int>\d{1,3}(?:[,.\u00a0 ]\d{3})+|\d+)(?:(?P<sep>[.,])(?P<frac>\d+))?"
    r"(?P<ord>st|nd|rd|th|º|ª)?(?![\w])"
)
_YEAR = range(1100, 2100)
# languages whose decimal separator is a comma (the others use a point)
_DECIMAL_COMMA = frozenset(("de", "es", "fr", "it", "pt", "pt_BR", "nl", "pl", "ru", "cs"))


@cache
def _num2words_languages() -> frozenset[str]:
    return frozenset(require("num2words").CONVERTER_CLASSES)


def num2words_language(lang: str) -> str | None:
    """num2words' code for an espeak-style language code (``"pt-br"`` -> ``"pt_BR"``,
    ``"en-us"`` -> ``"en"``), or None when num2words does not speak it."""
    known = _num2words_languages()
    parts = lang.replace("_", "-").split("-")
    full = parts[0].lower() + ("_" + parts[1].upper() if len(parts) > 1 else "")
    for code in (full, parts[0].lower()):
        if code in known:
            return code
    return None


def spell_numbers(text: str, *, lang: str) -> str:
    """``text`` with every number written as words in language ``lang`` (a bare four-digit
    number from 1100 to 2099 read as a year, ``3.5``/``3,5`` by the language's decimal
    separator, ``1st``/``1º`` as ordinals). Text is unchanged where num2words does not know
    the language (espeak-ng then reads the digits itself)."""
    code = num2words_language(lang)
    if code is None:
        return text
    from num2words import num2words

    def spell(match: re.Match[str]) -> str:
        whole, sep, frac, ordinal = match["int"], match["sep"], match["frac"], match["ord"]
        decimal_sep = "," if code.split("_")[0] in _DECIMAL_COMMA else "."
        if sep is not None and sep != decimal_sep and len(frac) == 3 and len(whole) <= 3:
            whole, sep, frac = whole + frac, None, None  # "1,000" in English, "1.000" in German
        digits = re.sub(r"\D", "", whole)
        number = int(digits)
        try:
            if sep is not None:
                return str(num2words(Decimal(f"{number}.{frac}"), lang=code))
            if ordinal:
                return str(num2words(number, lang=code, to="ordinal"))
            if number in _YEAR and len(digits) == 4 and digits == whole:
                return str(num2words(number, lang=code, to="year"))
            return str(num2words(number, lang=code))
        except (NotImplementedError, OverflowError):
            return match[0]

    return _NUMBER.sub(spell, text)


def to_ascii(text: str) -> str:
    """``text`` transliterated to ASCII by anyascii (``"José"`` -> ``"Jose"``)."""
    anyascii = require("anyascii").anyascii
    if not isinstance(text, str):
        raise ParameterError(f"text must be a string, got {type(text).__name__}")
    return str(anyascii(text))
