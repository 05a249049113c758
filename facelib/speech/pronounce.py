"""Words and their phones: transcript normalisation, the CMU pronunciation dictionary that
ships with pocketsphinx, and a letter-to-sound fallback for words missing from it."""

from __future__ import annotations

import re
from collections.abc import Mapping
from functools import cache
from pathlib import Path
from types import MappingProxyType

from facelib.errors import MissingExtraError, SpeechError
from facelib.optional import require
from facelib.speech.normalize import spell_numbers, to_ascii
from facelib.speech.tables import letter_to_sound_rules

__all__ = ["dictionary", "letter_to_sound", "normalize_english", "pronounce", "tokenize"]

_DIGITS = ("zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine")
_TOKEN = re.compile(r"[a-z]+(?:'[a-z]+)*|[0-9]|[,;:.!?]")


def normalize_english(text: str) -> str:
    """``text`` ready for the English dictionary: numbers spelt out by num2words ("2026" ->
    "twenty twenty-six") and letters transliterated by anyascii ("José" -> "Jose"). Without
    the ``speech`` extra the text is returned as it is (digits are then spelt one by one)."""
    try:
        return to_ascii(spell_numbers(text, lang="en"))
    except MissingExtraError:
        return text


def tokenize(text: str) -> list[str]:
    """Lower-case words of English ``text`` after :func:`normalize_english` (remaining
    digits spelt one by one), with the punctuation marks ``, ; : . ! ?`` kept as their own
    tokens. Raises :class:`SpeechError` for a transcript without words."""
    plain = normalize_english(text).lower().replace("-", " ")
    tokens = [_DIGITS[int(t)] if t.isdigit() else t for t in _TOKEN.findall(plain)]
    if not any(t[0].isalpha() for t in tokens):
        raise SpeechError(f"transcript {text!r} has no words")
    return tokens


def model_dir() -> Path:
    """The pocketsphinx model folder (``en-us/``, ``cmudict-en-us.dict``, phone LM)."""
    pocketsphinx = require("pocketsphinx")
    return Path(pocketsphinx.get_model_path()) / "en-us"


@cache
def dictionary() -> Mapping[str, tuple[str, ...]]:
    """The CMU dictionary of the pocketsphinx en-us model: word -> first pronunciation
    (ARPAbet, no stress). Needs the ``speech`` extra."""
    path = model_dir() / "cmudict-en-us.dict"
    words: dict[str, tuple[str, ...]] = {}
    with path.open(encoding="utf-8") as fh:
        for line in fh:
            parts = line.split()
            if len(parts) >= 2 and "(" not in parts[0]:
                words[parts[0]] = tuple(parts[1:])
    return MappingProxyType(words)


def letter_to_sound(word: str) -> tuple[str, ...]:
    """A pronunciation guessed from spelling (``letter_to_sound.csv``), for words missing
    from the dictionary. A final silent ``e`` after a consonant is dropped."""
    letters = re.sub(r"[^a-z]", "", word.lower())
    if len(letters) > 2 and letters.endswith("e") and letters[-2] not in "aeiouy":
        letters = letters[:-1]
    phones: list[str] = []
    i = 0
    rules = letter_to_sound_rules()
    while i < len(letters):
        for graphemes, out in rules:
            if letters.startswith(graphemes, i):
                phones.extend(out)
                i += len(graphemes)
                break
        else:  # a letter without a rule cannot happen for a-z; skip defensively
            i += 1
    if not phones:
        raise SpeechError(f"cannot pronounce word {word!r}")
    return tuple(p for k, p in enumerate(phones) if k == 0 or p != phones[k - 1])


def pronounce(word: str) -> tuple[tuple[str, ...], bool]:
    """``(phones, from_dictionary)`` for a normalised word: the dictionary's pronunciation,
    else the letter-to-sound guess."""
    entry = dictionary().get(word)
    if entry is not None:
        return entry, True
    return letter_to_sound(word), False
